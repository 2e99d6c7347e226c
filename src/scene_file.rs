//! Scene files: TOML in, a checked [`Scene`] out.
//!
//! A scene names only what differs from the tutorial's defaults; unknown keys are
//! errors, so a typo is never silently ignored. Every number is checked (finite,
//! in range) and every mistake is reported with the file, the key and what would be
//! valid.

use std::path::Path;

use serde::Deserialize;

use crate::camera::Screen;
use crate::error::Error;
use crate::plane::Plane;
use crate::scene::{Light, Material, Object, Role, Scene, Shape};
use crate::sphere::Sphere;
use crate::Vec3;

/// The tutorial's figure-1 scene (`scenes/seed.toml`), built into the binary.
pub const SEED_TOML: &str = include_str!("../scenes/seed.toml");

/// The name errors and summaries use for the built-in scene.
pub const SEED_NAME: &str = "scenes/seed.toml (built in)";

/// Largest accepted image side, in pixels.
pub const MAX_SIDE: u32 = 16384;

/// Largest accepted image, in pixels: 7680 × 4320 (8K). A render peaks at about
/// [`PEAK_BYTES_PER_PIXEL`], so this one needs about 4 GB.
pub const MAX_PIXELS: u64 = 7680 * 4320;

/// Peak memory of a render and its files per pixel, measured: an 8000 × 6000
/// render peaked at 5.6 GB resident (`/usr/bin/time -v raystep render --width 8000
/// --height 6000`).
pub const PEAK_BYTES_PER_PIXEL: u64 = 120;

/// Largest magnitude accepted for any number in a scene: squares of coordinates
/// stay far inside float32's and float64's range.
pub const MAX_MAGNITUDE: f64 = 1e15;

/// Largest accepted `max_depth`.
pub const MAX_DEPTH: u32 = 64;

/// Largest scene file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// An image size from the command line, overriding the scene's `[image]`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SizeOverride {
    /// `--width`.
    pub width: Option<u32>,
    /// `--height`.
    pub height: Option<u32>,
}

/// The built-in figure-1 scene.
pub fn seed() -> Scene {
    parse(SEED_TOML, SEED_NAME).expect("the built-in scene is valid")
}

/// Read and check the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, Error> {
    load_sized(path, SizeOverride::default())
}

/// Read and check the scene file at `path`, at the size `size` asks for.
pub fn load_sized(path: &Path, size: SizeOverride) -> Result<Scene, Error> {
    let file = path.display().to_string();
    let fail = |message: String| Error::Scene {
        file: file.clone(),
        message,
    };
    let cannot = |e: std::io::Error| fail(format!("cannot read the scene file: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if meta.is_dir() {
        return Err(fail(
            "is a folder; give the path of a .toml scene file".into(),
        ));
    }
    // Read at most one byte past the limit: a device such as /dev/zero has no
    // length to check beforehand.
    let mut bytes = Vec::new();
    let file_handle = std::fs::File::open(path).map_err(cannot)?;
    std::io::Read::read_to_end(
        &mut std::io::Read::take(file_handle, MAX_FILE_BYTES + 1),
        &mut bytes,
    )
    .map_err(cannot)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(fail(format!(
            "is larger than {MAX_FILE_BYTES} bytes, the most a scene file may be"
        )));
    }
    let text = String::from_utf8(bytes)
        .map_err(|_| fail("is not a text file (not UTF-8); a scene file is TOML text".into()))?;
    parse_sized(&text, &file, size)
}

/// Check the TOML text of a scene; `file` names it in error messages.
pub fn parse(text: &str, file: &str) -> Result<Scene, Error> {
    parse_sized(text, file, SizeOverride::default())
}

/// Check the TOML text of a scene at the size `size` asks for (the size decides the
/// default screen, so it is settled before anything is checked).
pub fn parse_sized(text: &str, file: &str, size: SizeOverride) -> Result<Scene, Error> {
    let fail = |message: String| Error::Scene {
        file: file.to_string(),
        message,
    };
    let raw: SceneFile =
        toml::from_str(text).map_err(|e| fail(e.to_string().trim_end().to_string()))?;
    raw.check(size)
        .map_err(|message| match (size.width, size.height) {
            (None, None) => fail(message),
            _ if message.starts_with("--") => Error::Usage(message),
            _ => fail(message),
        })
}

/// Refuse an image size that is zero or too large, naming where each side came
/// from (`image.width` or `--width`).
pub fn check_image_size(width: (u32, &str), height: (u32, &str)) -> Result<(), String> {
    for (value, source) in [width, height] {
        if value == 0 || value > MAX_SIDE {
            return Err(format!(
                "{source} = {value}: must be from 1 to {MAX_SIDE} pixels"
            ));
        }
    }
    let pixels = u64::from(width.0) * u64::from(height.0);
    if pixels > MAX_PIXELS {
        let gigabytes = (pixels * PEAK_BYTES_PER_PIXEL) as f64 / 1e9;
        return Err(format!(
            "{} = {} and {} = {} make {pixels} pixels; raystep renders at most {MAX_PIXELS} \
             (7680 × 4320), since a render needs about {PEAK_BYTES_PER_PIXEL} bytes per pixel \
             and this one would need {gigabytes:.1} GB",
            width.1, width.0, height.1, height.0
        ));
    }
    Ok(())
}

/// Refuse a `max_depth` outside 1 to [`MAX_DEPTH`], naming where it came from.
pub fn check_max_depth(max_depth: u32, source: &str) -> Result<(), String> {
    if (1..=MAX_DEPTH).contains(&max_depth) {
        Ok(())
    } else {
        Err(format!(
            "{source} = {max_depth}: must be from 1 to {MAX_DEPTH}"
        ))
    }
}

/// Most samples per pixel (`--spp`): 32 × 32.
pub const MAX_SPP: u32 = 1024;

/// Refuse a sample count that is not a square from 1 to [`MAX_SPP`] (the samples
/// of a pixel form an n × n grid of strata).
pub fn check_spp(spp: u32) -> Result<(), String> {
    let n = spp.isqrt();
    if !(1..=MAX_SPP).contains(&spp) {
        Err(format!("--spp {spp}: must be from 1 to {MAX_SPP}"))
    } else if n * n != spp {
        Err(format!(
            "--spp {spp}: must be a square number (1, 4, 9, 16, …), so that the samples \
             form an n × n grid over the pixel; the nearest are {} and {}",
            n * n,
            (n + 1) * (n + 1)
        ))
    } else {
        Ok(())
    }
}

/// Three numbers `[x, y, z]`: exactly three, so that a fourth is an error, not
/// silently dropped.
#[derive(Clone, Copy, Debug)]
struct Triple([f64; 3]);

impl<'de> Deserialize<'de> for Triple {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Triple, D::Error> {
        let numbers = Vec::<f64>::deserialize(d)?;
        <[f64; 3]>::try_from(numbers.as_slice())
            .map(Triple)
            .map_err(|_| {
                serde::de::Error::custom(format!(
                    "expected three numbers [x, y, z], found {}",
                    numbers.len()
                ))
            })
    }
}

// ANCHOR: schema
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    image: Option<ImageKeys>,
    camera: CameraKeys,
    screen: Option<ScreenKeys>,
    light: LightKeys,
    render: Option<RenderKeys>,
    #[serde(default)]
    sphere: Vec<SphereKeys>,
    #[serde(default)]
    plane: Vec<PlaneKeys>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ImageKeys {
    width: Option<u32>,  // default 300
    height: Option<u32>, // default 200
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraKeys {
    position: Triple, // required
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScreenKeys {
    left: Option<f64>,   // default -1
    right: Option<f64>,  // default 1
    top: Option<f64>,    // default 1/ratio, ratio = width/height
    bottom: Option<f64>, // default -1/ratio
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightKeys {
    position: Triple,         // required
    ambient: Option<Triple>,  // default [1, 1, 1]
    diffuse: Option<Triple>,  // default [1, 1, 1]
    specular: Option<Triple>, // default [1, 1, 1]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderKeys {
    max_depth: Option<u32>, // default 3
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereKeys {
    center: Triple,           // required
    radius: f64,              // required, > 0
    ambient: Option<Triple>,  // default [0.1, 0.1, 0.1]
    diffuse: Option<Triple>,  // default [0.6, 0.6, 0.6]
    specular: Option<Triple>, // default [1, 1, 1]
    shininess: Option<f64>,   // default 100
    reflection: Option<f64>,  // default 0.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneKeys {
    sphere: Option<SphereShape>, // the tutorial's fake plane ...
    point: Option<Triple>,       // ... or a true plane through `point`
    normal: Option<Triple>,      //     with this normal
    // The same material keys as a sphere:
    ambient: Option<Triple>,  // default [0.1, 0.1, 0.1]
    diffuse: Option<Triple>,  // default [0.6, 0.6, 0.6]
    specular: Option<Triple>, // default [1, 1, 1]
    shininess: Option<f64>,   // default 100
    reflection: Option<f64>,  // default 0.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereShape {
    center: Triple,
    radius: f64,
}

// ANCHOR_END: schema

/// The material keys that `[[sphere]]` and `[[plane]]` share. (serde cannot both
/// flatten a shared struct and refuse unknown keys, so each section lists them.)
struct MaterialKeys {
    ambient: Option<Triple>,
    diffuse: Option<Triple>,
    specular: Option<Triple>,
    shininess: Option<f64>,
    reflection: Option<f64>,
}

/// Moves the material keys out of a `[[sphere]]` or `[[plane]]` entry.
macro_rules! material_keys {
    ($keys:expr) => {
        MaterialKeys {
            ambient: $keys.ambient,
            diffuse: $keys.diffuse,
            specular: $keys.specular,
            shininess: $keys.shininess,
            reflection: $keys.reflection,
        }
    };
}

impl SceneFile {
    fn check(self, size: SizeOverride) -> Result<Scene, String> {
        let image = self.image.unwrap_or(ImageKeys {
            width: None,
            height: None,
        });
        let width = match size.width {
            Some(w) => (w, "--width"),
            None => (image.width.unwrap_or(300), "image.width"),
        };
        let height = match size.height {
            Some(h) => (h, "--height"),
            None => (image.height.unwrap_or(200), "image.height"),
        };
        check_image_size(width, height)?;
        let (width, height) = (width.0, height.0);

        let camera = point(self.camera.position, "camera.position")?;
        if camera.z == 0.0 {
            return Err(
                "camera.position: z = 0 puts the eye on the screen, which lies in the plane \
                 z = 0; move the camera off it, e.g. position = [0, 0, 1]"
                    .into(),
            );
        }

        let screen = match self.screen {
            None => None,
            Some(keys) => Some(keys.check(width, height)?),
        };

        let light = Light {
            position: point(self.light.position, "light.position")?,
            ambient: colour(self.light.ambient, Vec3::ONE, "light.ambient")?,
            diffuse: colour(self.light.diffuse, Vec3::ONE, "light.diffuse")?,
            specular: colour(self.light.specular, Vec3::ONE, "light.specular")?,
        };

        let max_depth = self.render.and_then(|r| r.max_depth).unwrap_or(3);
        check_max_depth(max_depth, "render.max_depth")?;

        let mut objects = Vec::new();
        for (i, keys) in self.sphere.into_iter().enumerate() {
            let at = format!("[[sphere]] number {}", i + 1);
            objects.push(Object {
                shape: Shape::Sphere(sphere(keys.center, keys.radius, &at)?),
                material: material_keys!(keys).check(&at)?,
                role: Role::Sphere,
            });
        }
        for (i, keys) in self.plane.into_iter().enumerate() {
            let at = format!("[[plane]] number {}", i + 1);
            objects.push(Object {
                shape: keys.shape(&at)?,
                material: material_keys!(keys).check(&at)?,
                role: Role::Floor,
            });
        }

        Ok(Scene {
            width,
            height,
            camera,
            screen,
            light,
            max_depth,
            objects,
        })
    }
}

impl ScreenKeys {
    fn check(self, width: u32, height: u32) -> Result<Screen, String> {
        let d = Screen::for_image(width, height);
        let s = Screen {
            left: number(self.left.unwrap_or(d.left), "screen.left")?,
            right: number(self.right.unwrap_or(d.right), "screen.right")?,
            top: number(self.top.unwrap_or(d.top), "screen.top")?,
            bottom: number(self.bottom.unwrap_or(d.bottom), "screen.bottom")?,
        };
        if s.left >= s.right {
            return Err(format!(
                "screen: left ({}) must be less than right ({}); the screen would be empty or mirrored",
                s.left, s.right
            ));
        }
        if s.bottom >= s.top {
            return Err(format!(
                "screen: bottom ({}) must be less than top ({}); the screen would be empty or upside down",
                s.bottom, s.top
            ));
        }
        Ok(s)
    }
}

impl PlaneKeys {
    fn shape(&self, at: &str) -> Result<Shape, String> {
        match (&self.sphere, self.point, self.normal) {
            (Some(s), None, None) => Ok(Shape::Sphere(sphere(
                s.center,
                s.radius,
                &format!("{at}, sphere"),
            )?)),
            (None, Some(p), Some(n)) => {
                let normal = point(n, &format!("{at}, normal"))?;
                if normal.length_squared() == 0.0 || !normal.length_squared().is_finite() {
                    return Err(format!(
                        "{at}, normal: must be a non-zero vector of moderate size"
                    ));
                }
                // Any point of the plane names it; keep the one nearest the origin,
                // so that the numbers the plane is computed from are no larger than
                // the plane's distance from the origin.
                let normal = normal.normalize();
                let anchor = point(p, &format!("{at}, point"))?;
                Ok(Shape::Plane(Plane {
                    point: normal * anchor.dot(normal),
                    normal,
                }))
            }
            _ => Err(format!(
                "{at}: give either `sphere = {{ center = [x, y, z], radius = r }}` (the tutorial's \
                 fake plane) or both `point` and `normal` (a true plane), not both and not neither"
            )),
        }
    }
}

impl MaterialKeys {
    fn check(self, at: &str) -> Result<Material, String> {
        let key = |name: &str| format!("{at}, {name}");
        let shininess = number(self.shininess.unwrap_or(100.0), &key("shininess"))?;
        if shininess < 0.0 {
            return Err(format!(
                "{}: {shininess} must be 0 or more",
                key("shininess")
            ));
        }
        let reflection = number(self.reflection.unwrap_or(0.5), &key("reflection"))?;
        if !(0.0..=1.0).contains(&reflection) {
            return Err(format!(
                "{}: {reflection} must be from 0 (matte) to 1 (perfect mirror)",
                key("reflection")
            ));
        }
        Ok(Material {
            ambient: colour(self.ambient, Vec3::splat(0.1), &key("ambient"))?,
            diffuse: colour(self.diffuse, Vec3::splat(0.6), &key("diffuse"))?,
            specular: colour(self.specular, Vec3::ONE, &key("specular"))?,
            shininess,
            reflection,
        })
    }
}

fn number(value: f64, key: &str) -> Result<f64, String> {
    if !value.is_finite() {
        Err(format!("{key}: {value} is not a finite number"))
    } else if value.abs() > MAX_MAGNITUDE {
        Err(format!("{key}: {value} is larger than {MAX_MAGNITUDE:e} in magnitude, the most raystep accepts"))
    } else {
        Ok(value)
    }
}

fn point(value: Triple, key: &str) -> Result<Vec3, String> {
    for v in value.0 {
        number(v, key)?;
    }
    Ok(Vec3::from(value.0))
}

fn colour(value: Option<Triple>, default: Vec3, key: &str) -> Result<Vec3, String> {
    let Some(value) = value else {
        return Ok(default);
    };
    let c = point(value, key)?;
    if c.min_element() < 0.0 {
        return Err(format!(
            "{key}: {:?} has a negative component; colours are 0 or more",
            value.0
        ));
    }
    Ok(c)
}

fn sphere(center: Triple, radius: f64, at: &str) -> Result<Sphere, String> {
    let radius = number(radius, &format!("{at}, radius"))?;
    if radius <= 0.0 {
        return Err(format!("{at}, radius: {radius} must be greater than 0"));
    }
    Ok(Sphere {
        center: point(center, &format!("{at}, center"))?,
        radius,
    })
}
