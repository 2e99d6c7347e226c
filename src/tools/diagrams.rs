//! The book's diagrams, drawn as SVG by plain Rust: the camera and its screen, a
//! ray meeting a sphere, the step off a surface, the vectors of Blinn-Phong, the
//! mirrored direction, the fake plane's sag and the cancellation of the textbook
//! quadratic.
//!
//! Every number a diagram shows is computed by the crate's own functions: the
//! camera's grid and primary ray, the roots and discriminants of a sphere,
//! `step_off`, `factors`, `reflect`, the spheres' and planes' `intersect`; and
//! where a chapter quotes a scene, from that scene file. So a diagram cannot drift
//! from what the renderer does: `raystep figures` draws them beside the renders,
//! and `raystep figures --check` compares their bytes.
//!
//! The SVG is written as text, element by element (`Svg` below): no fonts are loaded
//! (labels ask for the reader's `sans-serif` and `serif`), nothing outside the file
//! is referred to, and there are no scripts. Coordinates are rounded to a tenth of
//! a pixel, so the bytes are the same on every machine.

use std::fmt::Write as _;
use std::ops::{Add, Mul, Sub};
use std::path::Path;

use crate::camera::Camera;
use crate::error::Error;
use crate::plane::Plane;
use crate::ray::Ray;
use crate::real::Vector;
use crate::scene::{Material, Object, Role, Scene, Shape};
use crate::shade::blinn_phong::factors;
use crate::shade::reflection::reflect;
use crate::shade::shadow::{
    step_off, Offset, POINT_UNITS, RADIUS_UNITS, SCENE_FACTOR, TUTORIAL_STEP,
};
use crate::sphere::{Method, Sphere};
use crate::Vec3;

/// One diagram of the book: an SVG file under `chapters/img/`.
#[derive(Clone, Copy, Debug)]
pub struct Diagram {
    /// The path under `chapters/img/`, without `.svg`, e.g. `ch02/camera`.
    pub name: &'static str,
    /// Draws it, returning the SVG text; scene files are read relative to the
    /// folder given (the repository's root).
    pub draw: fn(&Path) -> Result<String, Error>,
}

impl Diagram {
    /// Its file, relative to `chapters/img/`.
    pub fn file(&self) -> String {
        format!("{}.svg", self.name)
    }

    /// Its SVG text, drawn now; scene files are read relative to `root`.
    pub fn svg(&self, root: &Path) -> Result<String, Error> {
        (self.draw)(root)
    }
}

/// Every diagram of the book, by chapter.
pub const DIAGRAMS: &[Diagram] = &[
    Diagram {
        name: "ch02/camera",
        draw: camera,
    },
    Diagram {
        name: "ch03/discriminant",
        draw: discriminant,
    },
    Diagram {
        name: "ch04/step",
        draw: step,
    },
    Diagram {
        name: "ch05/half-vector",
        draw: half_vector,
    },
    Diagram {
        name: "ch06/mirror",
        draw: mirror,
    },
    Diagram {
        name: "ch07/sag",
        draw: sag,
    },
    Diagram {
        name: "ch09/cancellation",
        draw: cancellation,
    },
    Diagram {
        name: "ch09/bound",
        draw: bound,
    },
];

/// The scene file at `path` under `root`.
fn scene_at(root: &Path, path: &str) -> Result<Scene, Error> {
    crate::io::scene_file::load(&root.join(path))
}

/// The sphere of the first object of `scene` with `role` that is a sphere.
fn first_sphere(scene: &Scene, role: Role) -> Option<(Object, Sphere)> {
    scene.objects.iter().find_map(|o| match o.shape {
        Shape::Sphere(s) if o.role == role => Some((*o, s)),
        _ => None,
    })
}

/// A scene without the objects a diagram needs.
fn missing(path: &str, what: &str) -> Error {
    Error::Scene {
        file: path.to_string(),
        message: format!("the book's diagram needs {what} in this scene"),
    }
}

// ---------------------------------------------------------------------------
// Chapter 2: the camera, the screen and one pixel's ray.

/// The seed scene, whose camera and screen chapter 2's diagram draws.
pub const SEED: &str = "scenes/seed.toml";

/// Chapter 2 draws the scene's screen with the grid of an image this small,
/// (columns, rows): the scene's own 300 × 200 would be a blur of lines. It has
/// the same ratio, so the screen is the same.
pub const CAMERA_GRID: (u32, u32) = (6, 4);

/// The pixel whose ray chapter 2 draws: (row, column).
pub const CAMERA_PIXEL: (u32, u32) = (1, 4);

/// What chapter 2's diagram shows, as the crate computes it.
#[derive(Clone, Copy, Debug)]
pub struct CameraPicture {
    /// The scene's camera and screen, sampled by a grid of [`CAMERA_GRID`].
    pub camera: Camera,
    /// The point of the screen that [`CAMERA_PIXEL`] looks at.
    pub point: Vec3,
    /// The pixel's primary ray.
    pub ray: Ray,
}

/// The camera of `scene` with the grid of [`CAMERA_GRID`], and [`CAMERA_PIXEL`]'s
/// screen point and primary ray, by [`Camera::screen_point`] and
/// [`Camera::primary_ray`].
pub fn camera_picture(scene: &Scene) -> CameraPicture {
    let (width, height) = CAMERA_GRID;
    let camera = Camera {
        width,
        height,
        ..scene.camera()
    };
    let (row, col) = CAMERA_PIXEL;
    CameraPicture {
        camera,
        point: camera.screen_point::<f64>(row, col),
        ray: camera.primary_ray::<f64>(row, col),
    }
}

/// An orthographic view of the scene from the front right and above: a turn of
/// 53.13° about y, then 16.26° about the new x axis, angles whose cosines (0.6 and
/// 0.96) and sines (0.8 and 0.28) are exact decimals.
#[derive(Clone, Copy, Debug)]
pub struct View {
    /// Where the scene's origin is drawn.
    pub origin: Px,
    /// Pixels per unit of the scene.
    pub scale: f64,
}

impl View {
    /// Where the point `p` of the scene is drawn.
    pub fn at(&self, p: Vec3) -> Px {
        let right = 0.6 * p.x - 0.8 * p.z;
        let up = -0.224 * p.x + 0.96 * p.y - 0.168 * p.z;
        px(
            self.origin.x + self.scale * right,
            self.origin.y - self.scale * up,
        )
    }
}

/// The view chapter 2 is drawn in.
pub const CAMERA_VIEW: View = View {
    origin: px(300.0, 232.0),
    scale: 190.0,
};

fn camera(root: &Path) -> Result<String, Error> {
    Ok(draw_camera(&camera_picture(&scene_at(root, SEED)?)))
}

fn draw_camera(picture: &CameraPicture) -> String {
    let CameraPicture { camera, point, ray } = *picture;
    let (row, col) = CAMERA_PIXEL;
    let view = CAMERA_VIEW;
    let s = camera.screen;
    let mut svg = Svg::new(
        720,
        460,
        &format!(
            "The camera, the screen at z = 0 with the grid of a {} × {} image, and the ray \
             of pixel (row {row}, column {col})",
            camera.width, camera.height
        ),
    );
    let on_screen = |x: f64, y: f64| view.at(Vec3::new(x, y, 0.0));
    let corners = [
        on_screen(s.left, s.top),
        on_screen(s.right, s.top),
        on_screen(s.right, s.bottom),
        on_screen(s.left, s.bottom),
    ];
    let eye = view.at(camera.position);
    let sample = |row: u32, col: u32| view.at(camera.screen_point::<f64>(row, col));

    // The pyramid of sight, from the eye to the screen's corners.
    for corner in corners {
        svg.line(eye, corner, pen(PALE, 1.2).dashed());
    }
    // The ray beyond the screen first: the screen, drawn over it, hides its part
    // behind the screen.
    let beyond = ray.at(1.9 * (point - camera.position).length());
    svg.id("ray-beyond");
    svg.arrow(view.at(point), view.at(beyond), pen(RED, 2.5));
    svg.polygon(&corners, SCREEN_FILL, Some(pen(BLUE, 1.8)), 0.88);
    // The grid: a line through each column's samples and each row's.
    for c in 0..camera.width {
        svg.line(sample(0, c), sample(camera.height - 1, c), pen(GRID, 1.0));
    }
    for r in 0..camera.height {
        svg.line(sample(r, 0), sample(r, camera.width - 1), pen(GRID, 1.0));
    }
    for r in 0..camera.height {
        for c in 0..camera.width {
            svg.dot(sample(r, c), BLUE, 3.5);
        }
    }
    // Column numbers above the top edge, row numbers beyond the right edge.
    let small = font(13.0, BLUE, Anchor::Middle);
    for c in 0..camera.width {
        let label = if c == 0 {
            "*j* = 0".to_string()
        } else {
            c.to_string()
        };
        svg.text(sample(0, c) + px(0.0, -12.0), &label, small);
    }
    for r in 0..camera.height {
        let label = if r == 0 {
            "*i* = 0".to_string()
        } else {
            r.to_string()
        };
        let at = sample(r, camera.width - 1) + px(10.0, 10.0);
        svg.text(at, &label, font(13.0, BLUE, Anchor::Start));
    }
    // The ray from the eye to the pixel's point.
    svg.id("primary-ray");
    svg.polyline(&[eye, view.at(point)], pen(RED, 2.5));
    svg.dot(view.at(point), RED, 5.5);
    svg.dot(eye, INK, 6.0);

    let label = font(15.0, INK, Anchor::Start);
    svg.text(
        eye + px(-22.0, 28.0),
        &format!("camera *O* = {}", triple(camera.position, 3)),
        label,
    );
    svg.text(
        corners[0] + px(-6.0, -30.0),
        &format!("(left, top) = ({}, {})", dec(s.left, 3), dec(s.top, 3)),
        font(14.0, BLUE, Anchor::Middle),
    );
    svg.text(
        corners[2] + px(-10.0, 26.0),
        &format!(
            "(right, bottom) = ({}, {})",
            dec(s.right, 3),
            dec(s.bottom, 3)
        ),
        font(14.0, BLUE, Anchor::Middle),
    );
    svg.text(
        corners[3].lerp(corners[2], 0.5) + px(-18.0, 26.0),
        "screen, *z* = 0",
        font(15.0, BLUE, Anchor::End),
    );
    // The pixel's label, with a leader line to its point.
    let tag = px(470.0, 330.0);
    svg.line(view.at(point), tag + px(-4.0, -14.0), pen(RED, 1.0));
    svg.text(
        tag,
        &format!("pixel (row *i* = {row}, column *j* = {col})"),
        font(15.0, RED, Anchor::Start),
    );
    svg.text(
        tag + px(0.0, 20.0),
        &format!("looks at *P* = {}", triple(point, 3)),
        font(15.0, RED, Anchor::Start),
    );
    svg.text(
        view.at(beyond) + px(-10.0, -16.0),
        "ray *O* + *t*·*d*",
        font(15.0, RED, Anchor::Middle),
    );
    svg.text(
        view.at(beyond) + px(-20.0, 30.0),
        "*d* = (*P* − *O*) / ‖*P* − *O*‖",
        font(15.0, RED, Anchor::Middle),
    );
    axes(&mut svg, view, px(70.0, 410.0));
    svg.finish()
}

/// The x, y and z axes of `view`, from `at`.
fn axes(svg: &mut Svg, view: View, at: Px) {
    let origin = view.at(Vec3::ZERO);
    for (axis, name) in [(Vec3::X, "x"), (Vec3::Y, "y"), (Vec3::Z, "z")] {
        let tip = at + (view.at(axis * 0.22) - origin);
        svg.arrow(at, tip, pen(GREY, 1.5));
        let beyond = at + (tip - at) * 1.35 + px(-4.0, 5.0);
        svg.text(
            beyond,
            &format!("*{name}*"),
            font(15.0, GREY, Anchor::Start),
        );
    }
}

// ---------------------------------------------------------------------------
// Chapter 3: a ray and a sphere, both roots, and the three signs of Δ.

/// Chapter 3's sphere: centre (4, 0, 0), radius 1.5.
pub const ROOTS_SPHERE: Sphere = Sphere {
    center: Vec3::new(4.0, 0.0, 0.0),
    radius: 1.5,
};

/// The heights of chapter 3's three rays, which run along +x from x = 0: through
/// the sphere (Δ > 0), touching it (Δ = 0, exactly: every number involved is exact
/// in binary) and passing beside it (Δ < 0).
pub const ROOTS_HEIGHTS: [f64; 3] = [-0.9, 1.5, 2.1];

/// Chapter 3's three rays, through, touching and beside [`ROOTS_SPHERE`].
pub fn roots_rays() -> [Ray; 3] {
    ROOTS_HEIGHTS.map(|y| Ray::new(Vec3::new(0.0, y, 0.0), Vec3::X))
}

fn discriminant(_root: &Path) -> Result<String, Error> {
    let sphere = ROOTS_SPHERE;
    let rays = roots_rays();
    let mut svg = Svg::new(
        720,
        345,
        "A ray through a sphere with its two roots t1 and t2, a ray that touches it \
         (discriminant zero) and a ray that misses it (discriminant negative)",
    );
    let scale = 70.0;
    let at = |p: Vec3| px(52.0 + scale * p.x, 215.0 - scale * p.y);
    svg.text(
        px(20.0, 26.0),
        "‖*O* + *t*·*d* − *C*‖² = *r*²  ⟺  *t*² + *b*·*t* + *c* = 0",
        font(16.0, INK, Anchor::Start),
    );
    svg.text(
        px(700.0, 26.0),
        "discriminant Δ = *b*² − 4*c*",
        font(16.0, INK, Anchor::End),
    );
    svg.circle(
        at(sphere.center),
        scale * sphere.radius,
        SPHERE_FILL,
        Some(pen(SPHERE_EDGE, 2.0)),
    );
    // The centre, and the radius to the point the second ray touches.
    let touch = Vec3::new(sphere.center.x, ROOTS_HEIGHTS[1], 0.0);
    svg.line(at(sphere.center), at(touch), pen(GREY, 1.3).dashed());
    svg.dot(at(sphere.center), INK, 4.0);
    svg.text(
        at(sphere.center) + px(8.0, 18.0),
        "*C*",
        font(17.0, INK, Anchor::Start),
    );
    svg.text(
        at(sphere.center.lerp(touch, 0.5)) + px(8.0, 5.0),
        "*r*",
        font(17.0, GREY, Anchor::Start),
    );
    let end = 6.2;
    for ray in &rays {
        let delta = sphere.discriminant_naive(ray);
        let (colour, sign, meaning) = if delta > 0.0 {
            (RED, " > 0", "two crossings, at *t*₁ and *t*₂")
        } else if delta == 0.0 {
            (ORANGE, "", "one point: a touch, not a hit")
        } else {
            (GREY, " < 0", "no crossing: a miss")
        };
        svg.arrow(at(ray.origin), at(ray.at(end)), pen(colour, 2.2));
        svg.dot(at(ray.origin), colour, 4.5);
        svg.text(
            at(ray.origin) + px(-10.0, 6.0),
            "*O*",
            font(16.0, colour, Anchor::End),
        );
        let right = px(at(ray.at(end)).x + 14.0, at(ray.origin).y);
        svg.text(
            right + px(0.0, -3.0),
            &format!("Δ = {}{sign}", dec(delta, 2)),
            Font {
                bold: true,
                ..font(15.0, colour, Anchor::Start)
            },
        );
        svg.text(
            right + px(0.0, 16.0),
            meaning,
            font(13.0, colour, Anchor::Start),
        );
        if let Some((t1, t2)) = sphere.roots_naive(ray) {
            for (t, name, dx) in [(t1, "₁", -8.0), (t2, "₂", 8.0)] {
                svg.dot(at(ray.at(t)), colour, 5.0);
                let anchor = if dx < 0.0 { Anchor::End } else { Anchor::Start };
                svg.text(
                    at(ray.at(t)) + px(dx, 22.0),
                    &format!("*t*{name} = {}", dec(t, 2)),
                    font(15.0, colour, anchor),
                );
            }
        } else if delta == 0.0 {
            // The one root, −b/2: the distance along the ray to the centre's
            // closest point, the `h` of the stable method.
            let t = ray.direction.dot(sphere.center - ray.origin);
            svg.ring(at(ray.at(t)), colour);
            svg.text(
                at(ray.at(t)) + px(6.0, -10.0),
                &format!("*t* = {}", dec(t, 2)),
                font(15.0, colour, Anchor::Start),
            );
        }
    }
    Ok(svg.finish())
}

// ---------------------------------------------------------------------------
// Chapter 4: the shadow ray, the step along the normal, and a point that shadows
// itself without it.

/// The piece of surface chapter 4 draws: the top of a sphere of radius 20, seen
/// magnified.
pub const STEP_SPHERE: Sphere = Sphere {
    center: Vec3::new(0.0, -20.0, 0.0),
    radius: 20.0,
};

/// The step chapter 4 draws, in the units of [`STEP_SPHERE`]: far larger than the
/// tutorial's 1e-5, so that it can be seen.
pub const STEP_DRAWN: f64 = 0.9;

/// How far inside the surface chapter 4 draws a computed hit point: a rounding
/// error of about 1e-16, magnified even more than the step.
pub const ERROR_DRAWN: f64 = 0.7;

/// What chapter 4's diagram shows, as the crate computes it.
#[derive(Clone, Copy, Debug)]
pub struct StepPicture {
    /// The exact hit point P on the surface.
    pub point: Vec3,
    /// The outward unit normal there.
    pub normal: Vec3,
    /// Where the light is.
    pub light: Vec3,
    /// P moved off the surface by [`step_off`] with a fixed step of [`STEP_DRAWN`].
    pub shifted: Vec3,
    /// A computed hit point a rounding error ([`ERROR_DRAWN`]) inside the surface.
    pub inside: Vec3,
    /// The roots of the ray from `inside` towards the light
    /// ([`Sphere::roots_stable`]): one negative, one a tiny positive distance.
    pub inside_roots: (f64, f64),
}

/// Chapter 4's numbers.
pub fn step_picture() -> StepPicture {
    let sphere = STEP_SPHERE;
    let normal = Vec3::new(-0.15, 1.0, 0.0).normalize();
    let point = sphere.center + normal * sphere.radius;
    let light = point + Vec3::new(5.2, 5.6, 0.0);
    let surface = Object {
        shape: Shape::Sphere(sphere),
        material: MATTE,
        role: Role::Sphere,
    };
    let shifted = step_off(point, normal, &surface, Offset::Fixed(STEP_DRAWN));
    let inside = point - normal * ERROR_DRAWN;
    let towards_light = Ray::towards(inside, light);
    let inside_roots = sphere
        .roots_stable(&towards_light)
        .expect("a ray from inside a sphere crosses it");
    StepPicture {
        point,
        normal,
        light,
        shifted,
        inside,
        inside_roots,
    }
}

/// A material for objects that only lend their shape to a diagram.
const MATTE: Material = Material {
    ambient: Vec3::ZERO,
    diffuse: Vec3::ONE,
    specular: Vec3::ZERO,
    shininess: 1.0,
    reflection: 0.0,
};

fn step(_root: &Path) -> Result<String, Error> {
    let p = step_picture();
    let sphere = STEP_SPHERE;
    let mut svg = Svg::new(
        720,
        400,
        "With the step, the shadow ray leaves from P' = P + step times N; without it, a \
         computed point a rounding error inside the surface sends a shadow ray that meets \
         the same surface at a tiny distance",
    );
    let scale = 36.0;
    let title = Font {
        bold: true,
        ..font(16.0, INK, Anchor::Start)
    };
    let note = font(13.0, GREY, Anchor::Start);
    // Two panels 360 pixels wide, the exact hit point P drawn at `anchor` in each.
    for (panel, left) in [(0, 0.0), (1, 360.0)] {
        let anchor = px(left + [165.0, 130.0][panel], 300.0);
        let at = |v: Vec3| {
            let d = v - p.point;
            anchor + px(scale * d.x, -scale * d.y)
        };
        // The sphere's cap, sampled across the panel, filled down to the bottom.
        let r = sphere.radius;
        let mut cap: Vec<Px> = (0..=36)
            .map(|i| {
                let x = p.point.x + (left + 10.0 * f64::from(i) - anchor.x) / scale;
                at(Vec3::new(x, sphere.center.y + (r * r - x * x).sqrt(), 0.0))
            })
            .collect();
        let edge = cap.clone();
        cap.push(px(left + 360.0, 400.0));
        cap.push(px(left, 400.0));
        svg.polygon(&cap, SPHERE_FILL, None, 1.0);
        svg.polyline(&edge, pen(SPHERE_EDGE, 2.0));
        if panel == 1 {
            svg.text(
                px(left + 345.0, 388.0),
                "inside the sphere",
                font(13.0, SPHERE_EDGE, Anchor::End),
            );
        }
        svg.circle(at(p.light), 11.0, LIGHT_FILL, Some(pen(ORANGE, 1.5)));
        svg.text(
            at(p.light) + px(-16.0, 5.0),
            "light",
            font(14.0, ORANGE, Anchor::End),
        );
        let start = [p.shifted, p.inside][panel];
        let towards = Ray::towards(start, p.light);
        let reach = (p.light - start).length() - 0.45;
        svg.arrow(at(start), at(towards.at(reach)), pen(ORANGE, 2.2));
        svg.text(
            at(towards.at(0.5 * reach)) + px(10.0, 10.0),
            "shadow ray",
            font(14.0, ORANGE, Anchor::Start),
        );
        if panel == 0 {
            svg.text(px(left + 20.0, 28.0), "With the step", title);
            svg.text(
                px(left + 20.0, 50.0),
                "The ray starts clear of the surface:",
                note,
            );
            svg.text(
                px(left + 20.0, 67.0),
                "it finds only what lies in its way.",
                note,
            );
            svg.text(
                px(left + 20.0, 84.0),
                &format!("(The step, {:e}, is drawn far larger.)", TUTORIAL_STEP),
                note,
            );
            let tip = p.point + p.normal * 2.6;
            svg.arrow(at(p.point), at(tip), pen(INK, 1.8));
            svg.text(
                at(tip) + px(-10.0, 4.0),
                "*N*",
                font(17.0, INK, Anchor::End),
            );
            svg.dot(at(p.point), INK, 4.5);
            svg.text(
                at(p.point) + px(10.0, 20.0),
                "*P*",
                font(17.0, INK, Anchor::Start),
            );
            svg.dot(at(p.shifted), ORANGE, 4.5);
            svg.text(
                at(p.shifted) + px(-12.0, 6.0),
                "*P*′ = *P* + step·*N*",
                font(15.0, INK, Anchor::End),
            );
        } else {
            svg.text(px(left + 20.0, 28.0), "Without the step", title);
            svg.text(
                px(left + 20.0, 50.0),
                "The ray starts a rounding error inside:",
                note,
            );
            svg.text(
                px(left + 20.0, 67.0),
                "it meets its own surface first.",
                note,
            );
            svg.text(
                px(left + 20.0, 84.0),
                "(The error, about 1e-16, is drawn far larger.)",
                note,
            );
            let (_, t) = p.inside_roots;
            let crossing = towards.at(t);
            svg.ring(at(p.point), INK);
            svg.text(
                at(p.point) + px(-12.0, -10.0),
                "exact hit point",
                font(14.0, INK, Anchor::End),
            );
            svg.dot(at(p.inside), INK, 4.5);
            svg.text(
                at(p.inside) + px(20.0, 30.0),
                "computed *P*, a rounding",
                font(14.0, INK, Anchor::Middle),
            );
            svg.text(
                at(p.inside) + px(20.0, 47.0),
                "error inside the surface",
                font(14.0, INK, Anchor::Middle),
            );
            svg.cross(at(crossing), RED);
            svg.text(
                at(crossing) + px(32.0, -31.0),
                "meets its own surface",
                font(14.0, RED, Anchor::Start),
            );
            svg.text(
                at(crossing) + px(32.0, -14.0),
                "at a tiny *t*",
                font(14.0, RED, Anchor::Start),
            );
        }
    }
    svg.line(px(360.0, 12.0), px(360.0, 400.0), pen(PALE, 1.5));
    Ok(svg.finish())
}

// ---------------------------------------------------------------------------
// Chapter 5: N, L, V and the half vector H at a point of the red sphere.

/// What chapter 5's diagram shows, as the crate computes it: a point of the seed
/// scene's red sphere in the plane through its centre, the camera and the light,
/// so that all four vectors lie in the plane of the drawing.
#[derive(Clone, Copy, Debug)]
pub struct HalfVectorPicture {
    /// The red sphere.
    pub sphere: Sphere,
    /// The point P on it.
    pub point: Vec3,
    /// N, the outward unit normal at P.
    pub normal: Vec3,
    /// L = normalize(light − P′), from P moved off the surface by [`step_off`]
    /// with the default offset, as the renderer computes it.
    pub to_light: Vec3,
    /// V = normalize(camera − P).
    pub to_viewer: Vec3,
    /// H = normalize(L + V).
    pub half: Vec3,
    /// Phong's R: the direction from the light, −L, mirrored about N by [`reflect`].
    pub mirrored: Vec3,
    /// L·N and N·H, by [`factors`].
    pub factors: (f64, f64),
}

/// Chapter 5's point: the normal a quarter of the way from the direction of the
/// camera to that of the light, as seen from the red sphere's centre.
pub fn half_vector_picture(scene: &Scene) -> Option<HalfVectorPicture> {
    let (object, sphere) = first_sphere(scene, Role::Sphere)?;
    let (camera, light) = (scene.camera, scene.light.position);
    let from_centre = |to: Vec3| (to - sphere.center).normalize();
    let normal = (from_centre(camera) * 0.75 + from_centre(light) * 0.25).normalize();
    let point = sphere.center + normal * sphere.radius;
    let shifted = step_off(point, normal, &object, Offset::default());
    let to_light = (light - shifted).normalize();
    let to_viewer = (camera - point).normalize();
    Some(HalfVectorPicture {
        sphere,
        point,
        normal,
        to_light,
        to_viewer,
        half: (to_light + to_viewer).normalize(),
        mirrored: reflect(-to_light, normal),
        factors: factors(normal, to_light, to_viewer),
    })
}

fn half_vector(root: &Path) -> Result<String, Error> {
    let scene = scene_at(root, SEED)?;
    let p = half_vector_picture(&scene).ok_or_else(|| missing(SEED, "a sphere"))?;
    // The drawing's axes: N up, and across it the direction in the plane of N and
    // V, so that V leans to the right.
    let up = p.normal;
    let across = (p.to_viewer - up * p.to_viewer.dot(up)).normalize();
    let (origin, unit) = (px(330.0, 330.0), 215.0);
    let at = |v: Vec3| origin + px(unit * v.dot(across), -unit * v.dot(up));
    let mut svg = Svg::new(
        720,
        400,
        "The unit vectors N, L, V and the half vector H at a point of the red sphere",
    );
    let centre = at(p.sphere.center - p.point);
    svg.circle(
        centre,
        unit * p.sphere.radius,
        SPHERE_FILL,
        Some(pen(SPHERE_EDGE, 2.0)),
    );
    let note = font(13.0, GREY, Anchor::Start);
    svg.text(
        px(20.0, 28.0),
        "A point *P* of the red sphere of figure 1,",
        note,
    );
    svg.text(
        px(20.0, 45.0),
        "in the plane of its centre, the camera and the light",
        note,
    );
    // L + V: the chord from L's tip to V's tip, whose middle H points at.
    svg.line(at(p.to_light), at(p.to_viewer), pen(GREY, 1.2).dashed());
    let (l_dot_n, n_dot_h) = p.factors;
    let dir = |v: Vec3| p2(v, up, across);
    svg.arc(origin, 70.0, dir(p.normal), dir(p.half), pen(GREEN, 1.5));
    svg.arc(
        origin,
        120.0,
        dir(p.normal),
        dir(p.to_light),
        pen(ORANGE, 1.3),
    );
    svg.arrow(origin, at(p.mirrored), pen(PURPLE, 1.6).dashed());
    svg.arrow(origin, at(p.normal), pen(INK, 2.4));
    svg.arrow(origin, at(p.to_light), pen(ORANGE, 2.4));
    svg.arrow(origin, at(p.to_viewer), pen(BLUE, 2.4));
    svg.arrow(origin, at(p.half), pen(GREEN, 2.4));
    svg.dot(origin, INK, 4.5);
    svg.text(
        origin + px(-2.0, 26.0),
        "*P*",
        font(17.0, INK, Anchor::Middle),
    );
    svg.text(
        at(p.normal) + px(2.0, -10.0),
        "*N*",
        font(18.0, INK, Anchor::Middle),
    );
    svg.text(
        at(p.to_light) + px(-10.0, 0.0),
        "*L*, to the light",
        font(15.0, ORANGE, Anchor::End),
    );
    svg.text(
        at(p.to_viewer) + px(10.0, 4.0),
        "*V*, to the camera",
        font(15.0, BLUE, Anchor::Start),
    );
    svg.text(
        at(p.half) + px(-8.0, -10.0),
        "*H* = normalize(*L* + *V*)",
        font(15.0, GREEN, Anchor::End),
    );
    svg.text(
        at(p.mirrored) + px(10.0, 6.0),
        "*R*: −*L* mirrored (Phong)",
        font(14.0, PURPLE, Anchor::Start),
    );
    let number = |colour| font(15.0, colour, Anchor::Start);
    svg.text(
        px(480.0, 300.0),
        &format!("*L*·*N* = {}", dec(l_dot_n, 3)),
        number(ORANGE),
    );
    svg.text(
        px(480.0, 322.0),
        &format!("*N*·*H* = {}", dec(n_dot_h, 3)),
        number(GREEN),
    );
    svg.text(
        px(480.0, 344.0),
        &format!("*P* = {}", triple(p.point, 3)),
        number(INK),
    );
    Ok(svg.finish())
}

/// The drawing's direction (y down) of `v`, with `up` and `across` its axes.
fn p2(v: Vec3, up: Vec3, across: Vec3) -> Px {
    px(v.dot(across), -v.dot(up))
}

// ---------------------------------------------------------------------------
// Chapter 6: the mirrored direction.

/// The incoming direction chapter 6 draws, a unit vector.
pub const MIRROR_IN: Vec3 = Vec3::new(0.8, -0.6, 0.0);

/// The mirror's unit normal in chapter 6.
pub const MIRROR_NORMAL: Vec3 = Vec3::Y;

fn mirror(_root: &Path) -> Result<String, Error> {
    let (d, n) = (MIRROR_IN, MIRROR_NORMAL);
    let r = reflect(d, n);
    let mut svg = Svg::new(
        720,
        360,
        "The mirrored direction r = d − 2(d·N)N: the part of d along the surface is kept, \
         the part along the normal reversed",
    );
    let (origin, unit) = (px(300.0, 230.0), 170.0);
    let at = |v: Vec3| origin + px(unit * v.x, -unit * v.y);
    // The mirror, hatched below.
    svg.line(px(40.0, origin.y), px(680.0, origin.y), pen(INK, 2.5));
    for i in 0..32 {
        let x = 48.0 + 20.0 * f64::from(i);
        svg.line(
            px(x, origin.y + 2.0),
            px(x - 12.0, origin.y + 14.0),
            pen(GREY, 1.0),
        );
    }
    svg.text(
        px(670.0, origin.y - 10.0),
        "mirror",
        font(14.0, INK, Anchor::End),
    );
    // d continued below the surface, and the correction back up to r.
    svg.arrow(origin, at(d), pen(RED, 1.5).dashed());
    svg.text(
        at(d * 0.55) + px(-10.0, 20.0),
        "*d*, continued",
        font(14.0, RED, Anchor::End),
    );
    svg.arrow(at(d), at(r), pen(PURPLE, 2.2));
    svg.text(
        at(d.lerp(r, 0.5)) + px(10.0, 40.0),
        "−2(*d*·*N*)*N*",
        font(15.0, PURPLE, Anchor::Start),
    );
    svg.arrow(at(-d), origin, pen(RED, 2.5));
    svg.arrow(origin, at(r), pen(GREEN, 2.5));
    svg.arrow(origin, at(n * 0.8), pen(INK, 2.0));
    svg.dot(origin, INK, 4.5);
    svg.text(
        at(n * 0.8) + px(0.0, -10.0),
        "*N*",
        font(17.0, INK, Anchor::Middle),
    );
    svg.text(
        at(-d * 0.55) + px(-8.0, 22.0),
        "*d*",
        font(17.0, RED, Anchor::End),
    );
    svg.text(
        at(r * 0.55) + px(10.0, 22.0),
        "*r*",
        font(17.0, GREEN, Anchor::Start),
    );
    // Equal angles on either side of the normal.
    svg.arc(
        origin,
        50.0,
        p2(n, Vec3::Y, Vec3::X),
        p2(-d, Vec3::Y, Vec3::X),
        pen(RED, 1.3),
    );
    svg.arc(
        origin,
        56.0,
        p2(n, Vec3::Y, Vec3::X),
        p2(r, Vec3::Y, Vec3::X),
        pen(GREEN, 1.3),
    );
    let text = |svg: &mut Svg, y: f64, line: &str, colour| {
        svg.text(px(470.0, y), line, font(15.0, colour, Anchor::Start));
    };
    text(&mut svg, 40.0, "*r* = *d* − 2(*d*·*N*)*N*", INK);
    text(
        &mut svg,
        64.0,
        &format!("*d* = ({}, {})", dec(d.x, 2), dec(d.y, 2)),
        RED,
    );
    text(
        &mut svg,
        86.0,
        &format!("*d*·*N* = {}", dec(d.dot(n), 2)),
        INK,
    );
    text(
        &mut svg,
        108.0,
        &format!("*r* = ({}, {})", dec(r.x, 2), dec(r.y, 2)),
        GREEN,
    );
    Ok(svg.finish())
}

// ---------------------------------------------------------------------------
// Chapter 7: the fake plane's sag below a true plane, towards the horizon.

/// The scene with the true plane that chapter 7 compares with [`SEED`]'s fake one.
pub const TRUE_PLANE: &str = "scenes/true-plane.toml";

/// The column of the picture whose rays chapter 7 draws (seen from the side).
pub const SAG_COLUMN: u32 = 150;

/// The rows whose rays chapter 7 draws: the last rows of sky.
pub const SAG_ROWS: [u32; 4] = [99, 100, 101, 102];

/// How many times chapter 7 stretches heights against distances.
pub const SAG_STRETCH: f64 = 25.0;

/// One row's primary ray in chapter 7, and where it meets each floor.
#[derive(Clone, Copy, Debug)]
pub struct SagRow {
    /// The row.
    pub row: u32,
    /// Its primary ray, through column [`SAG_COLUMN`].
    pub ray: Ray,
    /// Distance to the fake floor, if the ray meets it ([`Sphere::intersect`]).
    pub fake: Option<f64>,
    /// Distance to the true plane ([`Plane::intersect`]).
    pub true_plane: Option<f64>,
}

/// What chapter 7's diagram shows, as the crate computes it.
#[derive(Clone, Debug)]
pub struct SagPicture {
    /// The camera's position.
    pub camera: Vec3,
    /// The picture's size, (width, height).
    pub size: (u32, u32),
    /// The fake floor of the seed scene.
    pub fake: Sphere,
    /// The true plane of `scenes/true-plane.toml`.
    pub plane: Plane,
    /// The rays of [`SAG_ROWS`].
    pub rows: Vec<SagRow>,
    /// How far the fake floor lies below the true plane at distances 1, 10 and 100
    /// from its top: the length of a vertical ray from the true plane down to it.
    pub drops: [(f64, f64); 3],
}

/// Chapter 7's numbers, from the seed scene and the true-plane scene.
pub fn sag_picture(seed: &Scene, true_plane: &Scene) -> Option<SagPicture> {
    let (_, fake) = first_sphere(seed, Role::Floor)?;
    let plane = true_plane.objects.iter().find_map(|o| match o.shape {
        Shape::Plane(p) if o.role == Role::Floor => Some(p),
        _ => None,
    })?;
    let camera = seed.camera();
    let rows = SAG_ROWS
        .iter()
        .map(|&row| {
            let ray = camera.primary_ray::<f64>(row, SAG_COLUMN);
            SagRow {
                row,
                ray,
                fake: fake.intersect(&ray, Method::default()),
                true_plane: plane.intersect(&ray),
            }
        })
        .collect();
    let top = fake.center + Vec3::Y * fake.radius;
    let drops = [1.0, 10.0, 100.0].map(|x| {
        let down = Ray::new(top - Vec3::Z * x, -Vec3::Y);
        let t = fake.intersect(&down, Method::default()).unwrap_or(f64::NAN);
        (x, t)
    });
    Some(SagPicture {
        camera: camera.position,
        size: (seed.width, seed.height),
        fake,
        plane,
        rows,
        drops,
    })
}

fn sag(root: &Path) -> Result<String, Error> {
    let seed = scene_at(root, SEED)?;
    let true_plane = scene_at(root, TRUE_PLANE)?;
    let p = sag_picture(&seed, &true_plane)
        .ok_or_else(|| missing(SEED, "a sphere for a floor, and a true plane in the other"))?;
    let (across, up) = (2.75, 2.75 * SAG_STRETCH);
    let far = 235.0;
    // Distance ahead of the camera (−z) to the right, height up.
    let at = |v: Vec3| px(40.0 + across * (p.camera.z - v.z), 100.0 - up * v.y);
    let mut svg = Svg::new(
        720,
        420,
        &format!(
            "Side view of figure 1's floor: the fake floor, a sphere of radius {}, curves \
             away below the true plane towards the horizon (heights stretched {} times)",
            dec(p.fake.radius, 2),
            SAG_STRETCH
        ),
    );
    let height = p.plane.point.y;
    let floor_at = |z: f64| {
        let (c, r) = (p.fake.center, p.fake.radius);
        let dz = z - c.z;
        Vec3::new(0.0, c.y + (r * r - dz * dz).sqrt(), z)
    };
    // The fake floor, filled below.
    let mut ground: Vec<Px> = (0..=48)
        .map(|i| at(floor_at(p.camera.z - far * f64::from(i) / 48.0)))
        .collect();
    let edge = ground.clone();
    ground.push(px(ground[48].x, 420.0));
    ground.push(px(ground[0].x, 420.0));
    svg.polygon(&ground, FLOOR_FILL, None, 1.0);
    svg.polyline(&edge, pen(GREY, 2.2));
    // The true plane.
    let level = |distance: f64| at(Vec3::new(0.0, height, p.camera.z - distance));
    svg.line(level(0.0), level(far), pen(BLUE, 2.0));
    svg.text(
        level(0.0) + px(4.0, 27.0),
        &format!("true plane, *y* = {}", dec(height, 2)),
        font(14.0, BLUE, Anchor::Start),
    );
    svg.text(
        px(at(floor_at(p.camera.z - far)).x, 400.0),
        &format!(
            "fake floor: a sphere of radius {}, centre {}",
            dec(p.fake.radius, 2),
            triple(p.fake.center, 1)
        ),
        font(14.0, INK, Anchor::End),
    );
    // The sag at distance 100 from the top.
    let (x, t) = p.drops[2];
    let high = Vec3::new(0.0, height, p.fake.center.z - x);
    svg.line(at(high), at(high - Vec3::Y * t), pen(INK, 1.2));
    svg.text(
        at(high - Vec3::Y * (0.5 * t)) + px(8.0, 5.0),
        &format!("{} lower at {}", dec(t, 2), dec(x, 0)),
        font(13.0, INK, Anchor::Start),
    );
    // The rays of the last rows of sky, each with its line in the key.
    let key = font(14.0, INK, Anchor::Start);
    let colours = [GREY, PURPLE, ORANGE, RED];
    for (i, (row, colour)) in p.rows.iter().zip(colours).enumerate() {
        // Up to the fake floor, or as far as the drawing goes.
        let end = row.fake.unwrap_or(far / -row.ray.direction.z);
        svg.line(at(row.ray.origin), at(row.ray.at(end)), pen(colour, 1.8));
        if let Some(t) = row.true_plane {
            svg.ring(at(row.ray.at(t)), colour);
        }
        if let Some(t) = row.fake {
            svg.dot(at(row.ray.at(t)), colour, 5.0);
        } else {
            svg.text(
                at(row.ray.at(end)) + px(-2.0, -7.0),
                &row.row.to_string(),
                font(13.0, colour, Anchor::End),
            );
        }
        let what = match (row.fake, row.true_plane) {
            (None, None) => "sky over both floors".to_string(),
            (None, Some(t)) => format!("the true plane at {}, over the fake floor", dec(t, 0)),
            (Some(f), Some(t)) => format!(
                "the fake floor at {}, the true plane at {}",
                dec(f, 0),
                dec(t, 0)
            ),
            (Some(f), None) => format!("the fake floor at {}, over the true plane", dec(f, 0)),
        };
        let y = 278.0 + 20.0 * i as f64;
        svg.line(px(60.0, y - 5.0), px(84.0, y - 5.0), pen(colour, 2.5));
        svg.text(px(92.0, y), &format!("row {}: {what}", row.row), key);
    }
    svg.ring(px(72.0, 353.0), INK);
    svg.text(px(92.0, 358.0), "meets the true plane", key);
    svg.dot(px(262.0, 353.0), INK, 5.0);
    svg.text(px(276.0, 358.0), "meets the fake floor", key);
    svg.dot(at(p.camera), INK, 5.0);
    svg.text(
        at(p.camera) + px(4.0, -12.0),
        &format!("camera {}", triple(p.camera, 2)),
        font(14.0, INK, Anchor::Start),
    );
    let notes = [
        format!(
            "Seen from the side along column {SAG_COLUMN} of {} × {}; heights stretched {} times.",
            p.size.0, p.size.1, SAG_STRETCH
        ),
        format!(
            "The fake floor lies {} below the true plane at {}, {} at {}, {} at {}.",
            dec(p.drops[0].1, 5),
            dec(p.drops[0].0, 0),
            dec(p.drops[1].1, 3),
            dec(p.drops[1].0, 0),
            dec(p.drops[2].1, 2),
            dec(p.drops[2].0, 0),
        ),
    ];
    for (i, note) in notes.iter().enumerate() {
        svg.text(
            px(20.0, 22.0 + 18.0 * i as f64),
            note,
            font(13.0, GREY, Anchor::Start),
        );
    }
    Ok(svg.finish())
}

// ---------------------------------------------------------------------------
// Chapter 9: the textbook discriminant cancels; the stable form does not.

/// The far sphere of chapter 9: a unit sphere 5,000 away.
pub const FAR_SPHERE: &str = "scenes/stress/far-sphere.toml";

/// The pixel of [`FAR_SPHERE`] chapter 9 follows, (row, column): its ray passes
/// near the sphere's centre, a sure hit.
pub const FAR_PIXEL: (u32, u32) = (60, 80);

/// The numbers of chapter 9's diagram: the terms of both discriminants for one
/// float32 ray, as the float32 code computes them and exactly (in float64, from
/// the same float32 ray and sphere).
#[derive(Clone, Copy, Debug)]
pub struct Cancellation {
    /// b² in float32, as [`Sphere::roots_naive`] computes it.
    pub b2: f32,
    /// 4c in float32.
    pub four_c: f32,
    /// b² − 4c in float32 ([`Sphere::discriminant_naive`]).
    pub delta: f32,
    /// b², 4c and b² − 4c in float64 from the same inputs: exact here.
    pub exact: (f64, f64, f64),
    /// r² and ‖f + h·d‖² in float32, as [`Sphere::roots_stable`] computes them.
    pub stable_terms: (f32, f32),
    /// Δ/4 = r² − ‖f + h·d‖² in float32 ([`Sphere::quarter_discriminant`]).
    pub quarter: f32,
    /// The same in float64 from the same inputs.
    pub quarter_exact: f64,
}

/// Chapter 9's numbers for `ray` against `sphere`, in float32.
pub fn cancellation_numbers(sphere: &Sphere<f32>, ray: &Ray<f32>) -> Cancellation {
    // The textbook terms, step by step as `roots_naive` computes them.
    let oc = ray.origin - sphere.center;
    let b = 2.0 * ray.direction.dot(oc);
    let c = oc.length_squared() - sphere.radius * sphere.radius;
    let (b2, four_c) = (b * b, 4.0 * c);
    // The stable terms, as `roots_stable` computes them (m = C − O = −f).
    let m = sphere.center - ray.origin;
    let h = ray.direction.dot(m);
    let closest = (ray.direction * h - m).length_squared();
    let r2 = sphere.radius * sphere.radius;
    // The same, exactly: every float32 number is a float64 number.
    let exact_sphere: Sphere = Sphere {
        center: sphere.center.to_f64(),
        radius: f64::from(sphere.radius),
    };
    let exact_ray: Ray = Ray {
        origin: ray.origin.to_f64(),
        direction: ray.direction.to_f64(),
    };
    let oc64 = exact_ray.origin - exact_sphere.center;
    let b64 = 2.0 * exact_ray.direction.dot(oc64);
    let c64 = oc64.length_squared() - exact_sphere.radius * exact_sphere.radius;
    Cancellation {
        b2,
        four_c,
        delta: b2 - four_c,
        exact: (b64 * b64, 4.0 * c64, b64 * b64 - 4.0 * c64),
        stable_terms: (r2, closest),
        quarter: r2 - closest,
        quarter_exact: exact_sphere.quarter_discriminant(&exact_ray),
    }
}

/// Chapter 9's sphere and ray, in float32, from [`FAR_SPHERE`].
pub fn far_ray(scene: &Scene) -> Option<(Sphere<f32>, Ray<f32>)> {
    let (object, _) = first_sphere(scene, Role::Sphere)?;
    let Shape::Sphere(sphere) = object.cast::<f32>().shape else {
        return None;
    };
    let (row, col) = FAR_PIXEL;
    Some((sphere, scene.camera().primary_ray::<f32>(row, col)))
}

fn cancellation(root: &Path) -> Result<String, Error> {
    let scene = scene_at(root, FAR_SPHERE)?;
    let (sphere, ray) = far_ray(&scene).ok_or_else(|| missing(FAR_SPHERE, "a sphere"))?;
    let n = cancellation_numbers(&sphere, &ray);
    let (row, col) = FAR_PIXEL;
    let mut svg = Svg::new(
        720,
        435,
        "In float32 the textbook discriminant b² − 4c is the difference of two numbers \
         that round to the same value; the stable form subtracts numbers near 1",
    );
    let bold = |colour| Font {
        bold: true,
        ..font(16.0, colour, Anchor::Start)
    };
    svg.text(
        px(20.0, 28.0),
        "Textbook: Δ = *b*² − 4*c*, in float32",
        bold(INK),
    );
    svg.text(
        px(20.0, 48.0),
        &format!(
            "pixel (row {row}, column {col}) of {FAR_SPHERE}: aimed at a unit sphere {} away",
            thousands(f64::from((sphere.center - ray.origin).length()))
        ),
        font(13.0, GREY, Anchor::Start),
    );
    // A number line near b², with every float32 number on it.
    let step = f64::from(ulp(n.four_c));
    let middle = f64::from(n.four_c);
    let (lo, hi) = (middle - 3.0 * step, middle + 3.0 * step);
    let (x0, x1, line_y) = (60.0, 660.0, 140.0);
    let x_of = |v: f64| x0 + (v - lo) / (hi - lo) * (x1 - x0);
    svg.line(px(x0 - 20.0, line_y), px(x1 + 20.0, line_y), pen(INK, 1.5));
    for k in -3..=3 {
        let v = middle + f64::from(k) * step;
        svg.line(
            px(x_of(v), line_y - 8.0),
            px(x_of(v), line_y + 8.0),
            pen(INK, 1.5),
        );
        svg.text(
            px(x_of(v), line_y + 26.0),
            &thousands(v),
            font(12.0, INK, Anchor::Middle),
        );
    }
    let (b2, four_c, delta) = n.exact;
    // Each term: where it is exactly (above the line), and the float32 number it
    // rounds to (on it).
    for (exact, rounded, name, colour, lift) in [
        (b2, n.b2, "*b*²", BLUE, 62.0),
        (four_c, n.four_c, "4*c*", ORANGE, 36.0),
    ] {
        let top = px(x_of(exact), line_y - lift);
        svg.polygon(
            &[top, top + px(-6.0, -10.0), top + px(6.0, -10.0)],
            colour,
            None,
            1.0,
        );
        svg.arrow(
            top + px(0.0, 2.0),
            px(x_of(f64::from(rounded)), line_y - 4.0),
            pen(colour, 1.5),
        );
        svg.text(
            top + px(12.0, -2.0),
            &format!("{name} = {} before rounding", thousands(exact)),
            font(14.0, colour, Anchor::Start),
        );
        svg.dot(px(x_of(f64::from(rounded)), line_y), colour, 5.0);
    }
    svg.text(
        px(20.0, 196.0),
        &format!(
            "float32 numbers here are {} apart: *b*² rounds to {}, and 4*c* is {}.",
            dec(step, 0),
            thousands(f64::from(n.b2)),
            thousands(f64::from(n.four_c)),
        ),
        font(14.0, INK, Anchor::Start),
    );
    svg.text(
        px(20.0, 216.0),
        &format!(
            "So Δ = {} (not above 0): a miss. Before rounding, Δ = {}: a hit.",
            dec(f64::from(n.delta), 0),
            dec(delta, 3)
        ),
        Font {
            bold: true,
            ..font(14.0, RED, Anchor::Start)
        },
    );

    // The stable form: the same question asked with numbers near 1.
    svg.text(
        px(20.0, 268.0),
        "Stable: Δ/4 = *r*² − ‖*f* + *h*·*d*‖², in float32",
        bold(INK),
    );
    let (r2, closest) = n.stable_terms;
    let (x0, x1, line_y) = (60.0, 660.0, 356.0);
    let x_of = |v: f64| x0 + v / 1.2 * (x1 - x0);
    svg.line(px(x0 - 20.0, line_y), px(x1 + 20.0, line_y), pen(INK, 1.5));
    for k in 0..=6 {
        let v = 0.2 * f64::from(k);
        svg.line(
            px(x_of(v), line_y - 6.0),
            px(x_of(v), line_y + 6.0),
            pen(INK, 1.2),
        );
        svg.text(
            px(x_of(v), line_y + 24.0),
            &dec(v, 1),
            font(12.0, INK, Anchor::Middle),
        );
    }
    for (value, name, colour, lift) in [
        (f64::from(r2), "*r*²", BLUE, 40.0),
        (f64::from(closest), "‖*f* + *h*·*d*‖²", ORANGE, 40.0),
    ] {
        let top = px(x_of(value), line_y - lift);
        svg.polygon(
            &[top, top + px(-6.0, -10.0), top + px(6.0, -10.0)],
            colour,
            None,
            1.0,
        );
        svg.line(top, px(x_of(value), line_y), pen(colour, 1.5));
        svg.text(
            top + px(10.0, -2.0),
            &format!("{name} = {}", dec(value, 6)),
            font(14.0, colour, Anchor::Start),
        );
        svg.dot(px(x_of(value), line_y), colour, 5.0);
    }
    // The difference, a span across most of the line.
    let span_y = line_y - 14.0;
    svg.line(
        px(x_of(f64::from(closest)), span_y),
        px(x_of(f64::from(r2)), span_y),
        pen(GREEN, 2.5),
    );
    svg.text(
        px(x_of(0.5 * f64::from(closest + r2)), span_y - 8.0),
        &format!(
            "Δ/4 = {} (float64: {}): a hit",
            dec(f64::from(n.quarter), 7),
            dec(n.quarter_exact, 7)
        ),
        font(14.0, GREEN, Anchor::Middle),
    );
    svg.text(
        px(20.0, line_y + 58.0),
        &format!(
            "float32 numbers here are about {:.0e} apart, and the two terms are far apart: no digit is lost.",
            f64::from(ulp(r2))
        ),
        font(14.0, INK, Anchor::Start),
    );
    Ok(svg.finish())
}

// ---------------------------------------------------------------------------
// Chapter 9: the bound, and what a step of that size costs at the terminator.

/// The scene whose sphere chapter 9's bound diagram draws, in float32.
pub const TINY_FAR: &str = "scenes/stress/tiny-far.toml";

/// What chapter 9's bound diagram shows, as the crate computes it in float32.
#[derive(Clone, Copy, Debug)]
pub struct BoundPicture {
    /// The sphere, as float32 stores it (exactly, in float64).
    pub sphere: Sphere,
    /// The unit normal drawn (where the terminator is, for a light to the side).
    pub normal: Vec3,
    /// The steps of `--offset scene` and `--offset auto`, as `step_off` takes
    /// them in float32, in scene units.
    pub steps: [f64; 2],
    /// For each step `h`, the largest |L·N| at which a shadow ray from the
    /// stepped-off point passes over the sphere: `√(1 − (r/(r + h))²)`.
    pub reach: [f64; 2],
}

/// Chapter 9's bound diagram's numbers: the sphere of [`TINY_FAR`] in float32,
/// stepped off by the book's `step_off` at a point of its side.
pub fn bound_picture(scene: &Scene) -> Option<BoundPicture> {
    let (object, _) = first_sphere(scene, Role::Sphere)?;
    let object32: Object<f32> = object.cast();
    let Shape::Sphere(s32) = object32.shape else {
        return None;
    };
    let normal = Vec3::new(0.6, 0.8, 0.0);
    let n32 = glam::Vec3::new(0.6, 0.8, 0.0);
    let point = s32.center + n32 * s32.radius;
    let sphere = Sphere {
        center: s32.center.to_f64(),
        radius: f64::from(s32.radius),
    };
    let steps = [Offset::Scene, Offset::Auto].map(|offset| {
        let shifted = step_off(point, n32, &object32, offset).to_f64();
        shifted.distance(sphere.center) - sphere.radius
    });
    let reach = steps.map(|h| (1.0 - (sphere.radius / (sphere.radius + h)).powi(2)).sqrt());
    Some(BoundPicture {
        sphere,
        normal,
        steps,
        reach,
    })
}

fn bound(root: &Path) -> Result<String, Error> {
    let scene = scene_at(root, TINY_FAR)?;
    let p = bound_picture(&scene).ok_or_else(|| missing(TINY_FAR, "a sphere"))?;
    let r = p.sphere.radius;
    let mut svg = Svg::new(
        720,
        380,
        &format!(
            "Two panels at true scale: a sphere of radius {} about 1,000 from the origin, in \
             float32. Left, the scene-sized step {} puts the shadow ray's origin {:.2} of a \
             radius out, and a shadow ray passes over the sphere up to |L·N| = {:.2}. Right, \
             the bound's step {} puts it {:.2} of a radius out: up to |L·N| = {:.2}",
            dec(r, 3),
            sci(p.steps[0]),
            p.steps[0] / r,
            p.reach[0],
            sci(p.steps[1]),
            p.steps[1] / r,
            p.reach[1]
        ),
    );
    let title = Font {
        bold: true,
        ..font(16.0, INK, Anchor::Start)
    };
    let note = font(13.0, GREY, Anchor::Start);
    let scale = 110.0 / r;
    let labels = [
        (
            "--offset scene",
            format!("{SCENE_FACTOR}·u·(max|Cᵢ| + r): the size of the scene"),
        ),
        (
            "--offset auto",
            format!("u·({RADIUS_UNITS}·r + {POINT_UNITS}·‖P‖): a bound of the error"),
        ),
    ];
    for (panel, left) in [(0usize, 0.0), (1, 360.0)] {
        let centre = px(left + 150.0, 240.0);
        let at = |v: Vec3| centre + px(scale * v.x, -scale * v.y);
        svg.circle(centre, scale * r, SPHERE_FILL, Some(pen(SPHERE_EDGE, 2.0)));
        let h = p.steps[panel];
        let on = p.normal * r;
        let out = p.normal * (r + h);
        svg.dot(at(on), INK, 4.0);
        svg.text(at(on) + px(-8.0, 16.0), "*S*", font(15.0, INK, Anchor::End));
        svg.line(at(on), at(out), pen(ORANGE, 2.0));
        svg.dot(at(out), ORANGE, 4.5);
        svg.text(
            at(out) + px(8.0, -6.0),
            "*O*′",
            font(15.0, INK, Anchor::Start),
        );
        // The shadow ray from O′ that just touches the sphere: every ray from O′
        // below it (towards the sphere's dark side, at a smaller |L·N|) passes over.
        let d = r + h;
        let tangent_angle = (r / d).acos();
        let base = p.normal.y.atan2(p.normal.x);
        let touch_angle = base - tangent_angle;
        let touch = Vec3::new(touch_angle.cos(), touch_angle.sin(), 0.0) * r;
        let towards = touch - out;
        let far = out + towards * (1.0 + 1.4 * r / towards.length());
        svg.arrow(at(out), at(far), pen(ORANGE, 1.8));
        svg.text(px(left + 20.0, 28.0), labels[panel].0, title);
        svg.text(px(left + 20.0, 50.0), &labels[panel].1, note);
        svg.text(
            px(left + 20.0, 70.0),
            &format!("step {} = {:.2}·r", sci(h), h / r),
            note,
        );
        svg.text(
            px(left + 20.0, 90.0),
            &format!("passes over up to |L·N| = {:.2}", p.reach[panel]),
            font(13.0, ORANGE, Anchor::Start),
        );
    }
    svg.text(
        px(20.0, 370.0),
        &format!(
            "Radius {}, centre about 1,000 from the origin, float32: true scale.",
            dec(r, 3)
        ),
        font(13.0, GREY, Anchor::Start),
    );
    Ok(svg.finish())
}

/// A short number in scientific notation, e.g. `3.8e-4`.
fn sci(v: f64) -> String {
    format!("{v:.1e}")
}

/// The distance from `x` to the next float32 number away from zero.
fn ulp(x: f32) -> f32 {
    f32::from_bits(x.abs().to_bits() + 1) - x.abs()
}

/// A whole number with thin spaces between groups of three digits.
fn thousands(v: f64) -> String {
    let digits = format!("{:.0}", v.abs());
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    if v < 0.0 {
        format!("−{out}")
    } else {
        out
    }
}

// ---------------------------------------------------------------------------
// Drawing: points, pens, and an SVG document written as text.

/// A point of a drawing, in pixels from its top-left corner (y grows downwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Px {
    /// Pixels from the left.
    pub x: f64,
    /// Pixels from the top.
    pub y: f64,
}

/// The point (x, y) of a drawing.
pub const fn px(x: f64, y: f64) -> Px {
    Px { x, y }
}

impl Add for Px {
    type Output = Px;
    fn add(self, o: Px) -> Px {
        px(self.x + o.x, self.y + o.y)
    }
}

impl Sub for Px {
    type Output = Px;
    fn sub(self, o: Px) -> Px {
        px(self.x - o.x, self.y - o.y)
    }
}

impl Mul<f64> for Px {
    type Output = Px;
    fn mul(self, k: f64) -> Px {
        px(self.x * k, self.y * k)
    }
}

impl Px {
    fn length(self) -> f64 {
        (self.x * self.x + self.y * self.y).sqrt()
    }

    fn unit(self) -> Px {
        self * (1.0 / self.length())
    }

    /// The point a fraction `f` of the way to `other`.
    fn lerp(self, other: Px, f: f64) -> Px {
        self + (other - self) * f
    }
}

const INK: &str = "#222222";
const GREY: &str = "#777777";
const PALE: &str = "#b8b8b8";
const RED: &str = "#c0392b";
const BLUE: &str = "#1f62a8";
const GRID: &str = "#9dbbdc";
const ORANGE: &str = "#c8660a";
const GREEN: &str = "#23853a";
const PURPLE: &str = "#7a44b0";
const SCREEN_FILL: &str = "#e4eef9";
const SPHERE_FILL: &str = "#f7dede";
const SPHERE_EDGE: &str = "#b03a3a";
const FLOOR_FILL: &str = "#e6e6e6";
const LIGHT_FILL: &str = "#ffd54a";

/// How a line is drawn.
#[derive(Clone, Copy, Debug)]
struct Pen {
    colour: &'static str,
    width: f64,
    dashed: bool,
}

const fn pen(colour: &'static str, width: f64) -> Pen {
    Pen {
        colour,
        width,
        dashed: false,
    }
}

impl Pen {
    const fn dashed(self) -> Pen {
        Pen {
            dashed: true,
            ..self
        }
    }

    /// The SVG attributes of this pen.
    fn attributes(&self) -> String {
        let dash = if self.dashed {
            format!(
                r#" stroke-dasharray="{} {}""#,
                n(4.0 * self.width + 2.0),
                n(3.0 * self.width + 2.0)
            )
        } else {
            String::new()
        };
        format!(
            r#" stroke="{}" stroke-width="{}"{dash} stroke-linecap="round" fill="none""#,
            self.colour,
            n(self.width)
        )
    }
}

/// Which end of a label its point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Anchor {
    Start,
    Middle,
    End,
}

/// How a label is written.
#[derive(Clone, Copy, Debug)]
struct Font {
    size: f64,
    colour: &'static str,
    anchor: Anchor,
    bold: bool,
}

const fn font(size: f64, colour: &'static str, anchor: Anchor) -> Font {
    Font {
        size,
        colour,
        anchor,
        bold: false,
    }
}

/// An SVG document being written, element by element.
struct Svg {
    width: u32,
    height: u32,
    title: String,
    body: String,
    /// The `id` of the next element written, if it has one.
    next_id: Option<&'static str>,
}

impl Svg {
    fn new(width: u32, height: u32, title: &str) -> Svg {
        Svg {
            width,
            height,
            title: title.to_string(),
            body: String::new(),
            next_id: None,
        }
    }

    /// Give the next element the `id` given (tests find elements by it).
    fn id(&mut self, id: &'static str) {
        self.next_id = Some(id);
    }

    /// Start an element: `<NAME id="…"`.
    fn open(&mut self, name: &str) {
        let _ = write!(self.body, "<{name}");
        if let Some(id) = self.next_id.take() {
            let _ = write!(self.body, r#" id="{id}""#);
        }
    }

    fn line(&mut self, a: Px, b: Px, pen: Pen) {
        self.open("line");
        let _ = writeln!(
            self.body,
            r#" x1="{}" y1="{}" x2="{}" y2="{}"{}/>"#,
            n(a.x),
            n(a.y),
            n(b.x),
            n(b.y),
            pen.attributes()
        );
    }

    fn polyline(&mut self, points: &[Px], pen: Pen) {
        self.open("polyline");
        let _ = writeln!(
            self.body,
            r#" points="{}"{}/>"#,
            point_list(points),
            pen.attributes()
        );
    }

    /// A closed shape filled with `fill` at `opacity`, outlined by `edge` if given.
    fn polygon(&mut self, points: &[Px], fill: &str, edge: Option<Pen>, opacity: f64) {
        self.open("polygon");
        let stroke = edge.map_or_else(String::new, |p| {
            p.attributes().replace(r#" fill="none""#, "")
        });
        let opacity = if opacity < 1.0 {
            format!(r#" fill-opacity="{opacity}""#)
        } else {
            String::new()
        };
        let _ = writeln!(
            self.body,
            r#" points="{}" fill="{fill}"{opacity}{stroke}/>"#,
            point_list(points),
        );
    }

    fn circle(&mut self, centre: Px, r: f64, fill: &str, edge: Option<Pen>) {
        self.open("circle");
        let stroke = edge.map_or_else(String::new, |p| {
            p.attributes().replace(r#" fill="none""#, "")
        });
        let _ = writeln!(
            self.body,
            r#" cx="{}" cy="{}" r="{}" fill="{fill}"{stroke}/>"#,
            n(centre.x),
            n(centre.y),
            n(r)
        );
    }

    /// A filled dot of radius `r`.
    fn dot(&mut self, centre: Px, colour: &str, r: f64) {
        self.circle(centre, r, colour, None);
    }

    /// A hollow dot: a point where something would be.
    fn ring(&mut self, centre: Px, colour: &'static str) {
        self.circle(centre, 5.0, "#ffffff", Some(pen(colour, 2.0)));
    }

    /// A small × at `centre`.
    fn cross(&mut self, centre: Px, colour: &'static str) {
        let (a, b) = (px(6.0, 6.0), px(6.0, -6.0));
        self.line(centre - a, centre + a, pen(colour, 2.5));
        self.line(centre - b, centre + b, pen(colour, 2.5));
    }

    /// A line from `from` to `to` with a head at `to`.
    fn arrow(&mut self, from: Px, to: Px, pen: Pen) {
        let along = (to - from).unit();
        let head = 9.0 + 2.0 * pen.width;
        let half = 3.0 + 1.3 * pen.width;
        let base = to - along * head;
        self.line(from, base + along * 1.0, pen);
        let side = px(-along.y, along.x) * half;
        self.polygon(&[to, base + side, base - side], pen.colour, None, 1.0);
    }

    /// An arc of radius `r` around `centre`, the short way from the direction
    /// `from` to the direction `to` (both in the drawing's axes, y down).
    fn arc(&mut self, centre: Px, r: f64, from: Px, to: Px, pen: Pen) {
        let (a, b) = (centre + from.unit() * r, centre + to.unit() * r);
        // With y down, a positive cross product turns clockwise on the page,
        // which is SVG's sweep flag 1.
        let sweep = u8::from(from.x * to.y - from.y * to.x > 0.0);
        self.open("path");
        let _ = writeln!(
            self.body,
            r#" d="M {} {} A {} {} 0 0 {sweep} {} {}"{}/>"#,
            n(a.x),
            n(a.y),
            n(r),
            n(r),
            n(b.x),
            n(b.y),
            pen.attributes()
        );
    }

    /// A label at `at` (its baseline). Parts between asterisks are mathematics,
    /// written in italic serif: `"camera *O*"`.
    fn text(&mut self, at: Px, label: &str, font: Font) {
        let anchor = match font.anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let weight = if font.bold {
            r#" font-weight="bold""#
        } else {
            ""
        };
        self.open("text");
        let _ = write!(
            self.body,
            r#" x="{}" y="{}" font-size="{}" fill="{}" text-anchor="{anchor}"{weight}>"#,
            n(at.x),
            n(at.y),
            n(font.size),
            font.colour
        );
        for (i, part) in label.split('*').enumerate() {
            if part.is_empty() {
                continue;
            }
            if i % 2 == 1 {
                let _ = write!(
                    self.body,
                    r#"<tspan font-family="serif" font-style="italic">{}</tspan>"#,
                    escape(part)
                );
            } else {
                self.body.push_str(&escape(part));
            }
        }
        self.body.push_str("</text>\n");
    }

    /// The whole document.
    fn finish(self) -> String {
        let (w, h) = (self.width, self.height);
        format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"15\">\n\
             <title>{}</title>\n\
             <rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>\n{}</svg>\n",
            escape(&self.title),
            self.body
        )
    }
}

/// A coordinate of a drawing: rounded to a tenth of a pixel, without a "-0".
fn n(v: f64) -> String {
    let r = (v * 10.0).round() / 10.0;
    if r == 0.0 {
        "0".to_string()
    } else {
        format!("{r}")
    }
}

fn point_list(points: &[Px]) -> String {
    points
        .iter()
        .map(|p| format!("{},{}", n(p.x), n(p.y)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A number for a label: at most `places` decimals, trailing zeros dropped, with a
/// true minus sign.
fn dec(v: f64, places: usize) -> String {
    let text = format!("{v:.places$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".to_string()
    } else {
        text.replace('-', "−")
    }
}

/// A point as "(x, y, z)", each to at most `places` decimals.
fn triple(v: Vec3, places: usize) -> String {
    format!(
        "({}, {}, {})",
        dec(v.x, places),
        dec(v.y, places),
        dec(v.z, places)
    )
}

/// `text` with the characters XML reserves escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cmp::Ordering;

    fn root() -> &'static Path {
        Path::new(env!("CARGO_MANIFEST_DIR"))
    }

    fn seed() -> Scene {
        scene_at(root(), SEED).unwrap()
    }

    fn drawn(name: &str) -> String {
        let diagram = DIAGRAMS.iter().find(|d| d.name == name).unwrap();
        diagram.svg(root()).unwrap()
    }

    /// Check that `svg` is well-formed XML as far as this module writes it: every
    /// tag closed in order, one root element, quoted attributes, `&` only in the
    /// four escapes [`escape`] writes.
    fn well_formed(svg: &str) -> Result<(), String> {
        let mut open: Vec<&str> = Vec::new();
        let mut roots = 0;
        let mut rest = svg;
        while let Some(start) = rest.find('<') {
            check_text(&rest[..start])?;
            let end = rest[start..].find('>').ok_or("a tag is not closed")? + start;
            let tag = &rest[start + 1..end];
            if !tag.matches('"').count().is_multiple_of(2) {
                return Err(format!("unbalanced quotes in <{tag}>"));
            }
            if let Some(name) = tag.strip_prefix('/') {
                match open.pop() {
                    Some(expected) if expected == name.trim() => {}
                    other => return Err(format!("</{name}> closes {other:?}")),
                }
            } else {
                let name = tag.split_whitespace().next().ok_or("an empty tag")?;
                let name = name.trim_end_matches('/');
                if open.is_empty() {
                    roots += 1;
                }
                if !tag.ends_with('/') {
                    open.push(name);
                }
            }
            rest = &rest[end + 1..];
        }
        check_text(rest)?;
        match (open.is_empty(), roots) {
            (true, 1) => Ok(()),
            _ => Err(format!("{roots} root elements, left open: {open:?}")),
        }
    }

    fn check_text(text: &str) -> Result<(), String> {
        for (i, _) in text.match_indices('&') {
            let entity = &text[i..];
            if !["&amp;", "&lt;", "&gt;", "&quot;"]
                .iter()
                .any(|e| entity.starts_with(e))
            {
                return Err(format!("a bare & in {text:?}"));
            }
        }
        Ok(())
    }

    #[test]
    fn the_checker_catches_what_it_should() {
        assert!(well_formed("<svg><g><line/></g></svg>\n").is_ok());
        assert!(well_formed("<svg><g></svg>").is_err());
        assert!(well_formed("<svg></svg><svg></svg>").is_err());
        assert!(well_formed(r#"<svg a="1></svg>"#).is_err());
        assert!(well_formed("<svg>a & b</svg>").is_err());
        assert!(well_formed("<svg>a &amp; b</svg>").is_ok());
    }

    #[test]
    fn every_diagram_is_a_well_formed_svg_that_refers_to_nothing_outside() {
        let mut names = Vec::new();
        for diagram in DIAGRAMS {
            let svg = diagram.svg(root()).unwrap();
            let name = diagram.name;
            well_formed(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(
                svg.starts_with(r#"<svg xmlns="http://www.w3.org/2000/svg" width=""#),
                "{name}"
            );
            // The namespace is the only address; no links, images, fonts or scripts.
            assert_eq!(svg.matches("http").count(), 1, "{name}");
            for banned in ["href", "url(", "<script", "<image", "@import", "<style"] {
                assert!(!svg.contains(banned), "{name} contains {banned}");
            }
            // It fits the book's width, and draws on white, whatever the theme.
            let width: u32 = svg.split('"').nth(3).unwrap().parse().unwrap();
            assert!(width <= 750, "{name}: {width} pixels wide");
            assert!(svg.contains(r##"fill="#ffffff"/>"##), "{name}");
            // Nothing is drawn outside the drawing, give or take a line's width.
            let height: f64 = svg.split('"').nth(5).unwrap().parse().unwrap();
            for (attribute, limit) in [(" x1=\"", width as f64), (" y1=\"", height)] {
                for value in svg.split(attribute).skip(1) {
                    let v: f64 = value.split('"').next().unwrap().parse().unwrap();
                    assert!((-2.0..=limit + 2.0).contains(&v), "{name}: {attribute}{v}");
                }
            }
            names.push(name);
        }
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
    }

    /// The numbers of `points="x,y x,y …"` in the element with `id`.
    fn points_of(svg: &str, id: &str) -> Vec<(f64, f64)> {
        let element = svg.split(&format!(r#"id="{id}""#)).nth(1).unwrap();
        let points = element.split(r#"points=""#).nth(1).unwrap();
        let points = points.split('"').next().unwrap();
        points
            .split(' ')
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect()
    }

    /// `(x1, y1, x2, y2)` of the `<line>` with `id`.
    fn line_of(svg: &str, id: &str) -> (f64, f64, f64, f64) {
        let element = svg.split(&format!(r#"id="{id}""#)).nth(1).unwrap();
        let value = |name: &str| -> f64 {
            let v = element.split(&format!(r#" {name}=""#)).nth(1).unwrap();
            v.split('"').next().unwrap().parse().unwrap()
        };
        (value("x1"), value("y1"), value("x2"), value("y2"))
    }

    #[test]
    fn chapter_2_draws_the_pixels_ray_through_the_point_the_camera_computes() {
        let scene = seed();
        let picture = camera_picture(&scene);
        let camera = picture.camera;
        // The scene's camera and screen, on a grid of the same ratio.
        assert_eq!(camera.position, Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(camera.screen, scene.camera().screen);
        let (w, h) = CAMERA_GRID;
        assert_eq!(w * scene.height, h * scene.width, "the same ratio");
        // The pixel's point is the screen point of the crate's camera, and its ray
        // goes from the camera through it.
        let (row, col) = CAMERA_PIXEL;
        assert_eq!(picture.point, camera.screen_point::<f64>(row, col));
        assert!((picture.point - Vec3::new(0.6, 2.0 / 9.0, 0.0)).length() < 1e-15);
        assert_eq!(picture.ray, camera.primary_ray::<f64>(row, col));
        assert!(
            (picture.ray.direction - (picture.point - camera.position).normalize()).length()
                < 1e-15
        );
        // In the drawing: from the eye to the pixel's point, then on beyond it in
        // the same direction.
        let svg = drawn("ch02/camera");
        let view = CAMERA_VIEW;
        let (eye, point) = (view.at(camera.position), view.at(picture.point));
        let ray = points_of(&svg, "primary-ray");
        let close = |(x, y): (f64, f64), p: Px| (x - p.x).abs() <= 0.05 && (y - p.y).abs() <= 0.05;
        assert!(close(ray[0], eye) && close(ray[1], point), "{ray:?}");
        let (x1, y1, x2, y2) = line_of(&svg, "ray-beyond");
        assert!(close((x1, y1), point), "{x1} {y1}");
        let (along, beyond) = (point - eye, px(x2 - x1, y2 - y1));
        let cross = along.x * beyond.y - along.y * beyond.x;
        assert!(cross.abs() / (along.length() * beyond.length()) < 1e-3);
        assert!(svg.contains("= (0.6, 0.222, 0)"));
    }

    #[test]
    fn chapter_3_rays_have_the_three_signs_of_the_discriminant() {
        let [through, touching, beside] = roots_rays();
        let s = ROOTS_SPHERE;
        let sign = |x: f64| x.partial_cmp(&0.0).unwrap();
        for (ray, expected) in [
            (through, Ordering::Greater),
            (touching, Ordering::Equal),
            (beside, Ordering::Less),
        ] {
            assert_eq!(sign(s.discriminant_naive(&ray)), expected);
            assert_eq!(sign(s.quarter_discriminant(&ray)), expected);
        }
        assert_eq!(s.discriminant_naive(&touching), 0.0, "exactly");
        // Both roots of the ray through, by both methods.
        let (t1, t2) = s.roots_naive(&through).unwrap();
        let (u1, u2) = s.roots_stable(&through).unwrap();
        assert!((t1 - 2.8).abs() < 1e-12 && (t2 - 5.2).abs() < 1e-12);
        assert!((t1 - u1).abs() < 1e-12 && (t2 - u2).abs() < 1e-12);
        // Only the ray through is a hit: a touch is not.
        assert_eq!(s.intersect(&through, Method::Naive), Some(t1));
        assert_eq!(s.intersect(&touching, Method::Naive), None);
        assert_eq!(s.intersect(&beside, Method::Naive), None);
        let svg = drawn("ch03/discriminant");
        for label in [
            "₁ = 2.8<",
            "₂ = 5.2<",
            "Δ = 5.76 &gt; 0<",
            "Δ = 0<",
            "Δ = −8.64 &lt; 0<",
        ] {
            assert!(svg.contains(label), "{label}");
        }
        // The caption says where the rays start.
        let chapter = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/chapters/03-intersection.md"
        ))
        .unwrap();
        let [a, b, c] = ROOTS_HEIGHTS.map(|y| y.to_string().replace('-', "−"));
        assert!(chapter.contains(&format!("from\n(0, y, 0) with y = {a}, {b} and {c}.")));
    }

    #[test]
    fn chapter_4_the_step_clears_the_surface_and_a_point_inside_meets_it_at_once() {
        let p = step_picture();
        let s = STEP_SPHERE;
        let from_centre = |v: Vec3| (v - s.center).length() - s.radius;
        assert!(from_centre(p.point).abs() < 1e-12, "P is on the surface");
        assert!((p.shifted - (p.point + p.normal * STEP_DRAWN)).length() < 1e-12);
        assert!(from_centre(p.shifted) > 0.0 && from_centre(p.inside) < 0.0);
        // From the stepped-off point, the ray to the light never meets the sphere.
        let clear = Ray::towards(p.shifted, p.light);
        assert!(s
            .roots_stable(&clear)
            .is_none_or(|(a, b)| a < 0.0 && b < 0.0));
        // From the point inside, it meets the surface at a small positive t (a
        // rounding error's worth, magnified) and behind the point.
        let (behind, ahead) = p.inside_roots;
        assert!(behind < 0.0 && ahead > 0.0 && ahead < 2.0 * ERROR_DRAWN);
        // The tutorial's rule, both roots positive, ignores that crossing (chapter
        // 4 explains where its acne shows instead); a rule that took the nearest
        // positive root would call the point shadowed by its own surface.
        let towards = Ray::towards(p.inside, p.light);
        assert_eq!(s.intersect(&towards, Method::Stable), None);
    }

    #[test]
    fn chapter_5_vectors_are_the_renderers_and_h_halves_the_angle_of_l_and_v() {
        let p = half_vector_picture(&seed()).unwrap();
        for v in [p.normal, p.to_light, p.to_viewer, p.half, p.mirrored] {
            assert!((v.length() - 1.0).abs() < 1e-15);
        }
        // All in the plane of the drawing.
        assert!(p.normal.cross(p.to_light).dot(p.to_viewer).abs() < 1e-12);
        // H makes the same angle with L as with V (on either side, a miss).
        assert!((p.half.dot(p.to_light) - p.half.dot(p.to_viewer)).abs() < 1e-15);
        // Lit and seen, with the factors Blinn-Phong uses.
        let (l_dot_n, n_dot_h) = p.factors;
        assert_eq!(l_dot_n, p.to_light.dot(p.normal));
        assert_eq!(n_dot_h, p.normal.dot(p.half));
        assert!(l_dot_n > 0.0 && p.to_viewer.dot(p.normal) > 0.0);
        // In one plane, Phong's angle (R to V) is exactly twice Blinn's (N to H).
        let phong = p.mirrored.dot(p.to_viewer).clamp(-1.0, 1.0).acos();
        let blinn = n_dot_h.clamp(-1.0, 1.0).acos();
        assert!((phong - 2.0 * blinn).abs() < 1e-9, "{phong} {blinn}");
        let svg = drawn("ch05/half-vector");
        assert!(svg.contains(&format!("= {}<", dec(l_dot_n, 3))));
        assert!(svg.contains(&format!("= {}<", dec(n_dot_h, 3))));
    }

    #[test]
    fn chapter_6_keeps_the_part_along_the_surface_and_reverses_the_part_along_n() {
        let r = reflect(MIRROR_IN, MIRROR_NORMAL);
        assert!((r - Vec3::new(0.8, 0.6, 0.0)).length() < 1e-15);
        let svg = drawn("ch06/mirror");
        assert!(svg.contains("= (0.8, 0.6)<") && svg.contains("= (0.8, −0.6)<"));
    }

    #[test]
    fn chapter_7_rows_100_and_101_meet_the_true_plane_and_pass_over_the_fake_floor() {
        let true_plane = scene_at(root(), TRUE_PLANE).unwrap();
        let p = sag_picture(&seed(), &true_plane).unwrap();
        assert_eq!(
            (p.fake.center, p.fake.radius),
            (Vec3::new(0.0, -9000.0, 0.0), 8999.3)
        );
        let hits: Vec<(u32, bool, bool)> = p
            .rows
            .iter()
            .map(|r| (r.row, r.fake.is_some(), r.true_plane.is_some()))
            .collect();
        assert_eq!(
            hits,
            [
                (99, false, false),
                (100, false, true),
                (101, false, true),
                (102, true, true)
            ],
            "the last row of sky is 101 on the fake floor, 99 on the true plane"
        );
        // The drops are the x²/(2R) chapter 7 quotes.
        for (x, drop) in p.drops {
            let estimate = x * x / (2.0 * p.fake.radius);
            assert!(
                (drop / estimate - 1.0).abs() < 0.01,
                "{x}: {drop} {estimate}"
            );
        }
        let svg = drawn("ch07/sag");
        assert!(svg.contains("0.00006 below the true plane at 1, 0.006 at 10"));
        assert!(svg.contains(&format!("stretched {SAG_STRETCH} times")));
    }

    #[test]
    fn chapter_9_the_textbook_discriminant_cancels_in_float32_and_the_stable_one_does_not() {
        let scene = scene_at(root(), FAR_SPHERE).unwrap();
        let (sphere, ray) = far_ray(&scene).unwrap();
        let n = cancellation_numbers(&sphere, &ray);
        // The diagram's numbers are the code's, to the bit.
        assert_eq!(n.delta.to_bits(), sphere.discriminant_naive(&ray).to_bits());
        assert_eq!(
            n.quarter.to_bits(),
            sphere.quarter_discriminant(&ray).to_bits()
        );
        // b² and 4c differ by 4 before rounding, and round to the same float32.
        let (b2, four_c, delta) = n.exact;
        assert_eq!((b2, four_c, delta), (100_040_004.0, 100_040_000.0, 4.0));
        assert_eq!(n.b2, n.four_c);
        assert_eq!(n.delta, 0.0);
        assert!(
            f64::from(ulp(n.b2)) > delta,
            "the difference is below one step"
        );
        // So the textbook method misses a sure hit, and the stable one finds it.
        assert_eq!(sphere.intersect(&ray, Method::Naive), None);
        assert!(sphere.intersect(&ray, Method::Stable).is_some());
        assert!((f64::from(n.quarter) - n.quarter_exact).abs() < 1e-6);
        let svg = drawn("ch09/cancellation");
        assert!(svg.contains("100,040,004 before rounding"));
        assert!(svg.contains("So Δ = 0 (not above 0): a miss. Before rounding, Δ = 4: a hit."));
    }

    /// The text of every label of `svg`, without its markup: `<text …>*t* = 4</text>`
    /// is "t = 4".
    fn labels(svg: &str) -> Vec<String> {
        svg.split("<text ")
            .skip(1)
            .map(|element| {
                let inner = &element[element.find('>').unwrap() + 1..];
                let inner = &inner[..inner.find("</text>").unwrap()];
                let mut plain = String::new();
                let mut in_tag = false;
                for ch in inner.chars() {
                    match ch {
                        '<' => in_tag = true,
                        '>' => in_tag = false,
                        _ if !in_tag => plain.push(ch),
                        _ => {}
                    }
                }
                plain
                    .replace("&gt;", ">")
                    .replace("&lt;", "<")
                    .replace("&amp;", "&")
            })
            .collect()
    }

    fn has_label(svg: &str, wanted: &str) -> bool {
        labels(svg).iter().any(|l| l == wanted)
    }

    /// `(x1, y1, x2, y2)` of every `<line>` drawn with `stroke` at `width`.
    fn lines_with(svg: &str, stroke: &str, width: &str) -> Vec<(f64, f64, f64, f64)> {
        let pen = format!(r#" stroke="{stroke}" stroke-width="{width}""#);
        svg.lines()
            .filter(|l| l.starts_with("<line") && l.contains(&pen))
            .map(|element| {
                let value = |name: &str| -> f64 {
                    let v = element.split(&format!(r#" {name}=""#)).nth(1).unwrap();
                    v.split('"').next().unwrap().parse().unwrap()
                };
                (value("x1"), value("y1"), value("x2"), value("y2"))
            })
            .collect()
    }

    #[test]
    fn chapter_2_labels_say_the_captions_grid_pixel_and_screen_corners() {
        // The caption: "the grid of a 6 × 4 image … pixel (row 1, column 4)"; the
        // seed scene's default screen: x from −1 to 1, y ±200/300.
        let svg = drawn("ch02/camera");
        assert!(svg.contains("<title>The camera, the screen at z = 0 with the grid of a 6 × 4 image, and the ray of pixel (row 1, column 4)</title>"));
        assert!(
            has_label(&svg, "pixel (row i = 1, column j = 4)"),
            "{:?}",
            labels(&svg)
        );
        assert!(
            has_label(&svg, "(left, top) = (−1, 0.667)"),
            "{:?}",
            labels(&svg)
        );
        assert!(
            has_label(&svg, "(right, bottom) = (1, −0.667)"),
            "{:?}",
            labels(&svg)
        );
    }

    #[test]
    fn chapter_3_the_touching_ray_meets_the_sphere_once_at_its_radius_end() {
        // The ray at height 1.5 along +x from x = 0 touches the sphere of radius 1.5
        // around (4, 0, 0) at (4, 1.5, 0): t = 4, the top of the radius drawn.
        let svg = drawn("ch03/discriminant");
        assert!(has_label(&svg, "t = 4"), "{:?}", labels(&svg));
        // The drawing puts (x, y) at (52 + 70x, 215 − 70y): C at (332, 215), the
        // touching point at (332, 110).
        let radius = lines_with(&svg, GREY, "1.3");
        assert_eq!(radius, [(332.0, 215.0, 332.0, 110.0)]);
    }

    #[test]
    fn chapter_4_each_shadow_ray_starts_where_its_panel_says() {
        // Left, from P′ = P + step·N; right, from the point a rounding error inside.
        // The drawing puts P at (165, 300) on the left, (490, 300) on the right, 36
        // pixels a unit, y up.
        let p = step_picture();
        let svg = drawn("ch04/step");
        let starts: Vec<(f64, f64)> = lines_with(&svg, ORANGE, "2.2")
            .iter()
            .map(|&(x1, y1, _, _)| (x1, y1))
            .collect();
        let drawn_at = |anchor: f64, v: Vec3| {
            let d = v - p.point;
            (n(anchor + 36.0 * d.x), n(300.0 - 36.0 * d.y))
        };
        let starts: Vec<(String, String)> = starts.iter().map(|&(x, y)| (n(x), n(y))).collect();
        assert_eq!(
            starts,
            [drawn_at(165.0, p.shifted), drawn_at(490.0, p.inside)]
        );
        // Right: the × where it meets its own surface, ahead of the point inside
        // (the positive root), towards the light.
        let (_, ahead) = p.inside_roots;
        assert!(ahead > 0.0);
        let crossing = Ray::towards(p.inside, p.light).at(ahead);
        let d = crossing - p.point;
        let (cx, cy) = (490.0 + 36.0 * d.x, 300.0 - 36.0 * d.y);
        let cross = lines_with(&svg, RED, "2.5");
        assert_eq!(cross.len(), 2, "{cross:?}");
        for (x1, y1, x2, y2) in cross {
            let (mx, my) = ((x1 + x2) / 2.0, (y1 + y2) / 2.0);
            assert!(
                (mx - cx).abs() <= 0.1 && (my - cy).abs() <= 0.1,
                "× at ({mx}, {my}), not ({cx}, {cy})"
            );
        }
    }

    #[test]
    fn chapter_5_the_normal_is_a_quarter_of_the_way_from_the_camera_to_the_light() {
        // N = normalize(¾·ĉ + ¼·l̂) for the unit directions ĉ, l̂ from the centre to
        // the camera and to the light: then |N × ĉ| / |N × l̂| = ¼ / ¾ (a sum of two
        // unit vectors weighted a and b makes angles whose sines are as b to a).
        let scene = seed();
        let p = half_vector_picture(&scene).unwrap();
        let c = (scene.camera - p.sphere.center).normalize();
        let l = (scene.light.position - p.sphere.center).normalize();
        let ratio = p.normal.cross(c).length() / p.normal.cross(l).length();
        assert!((ratio - 1.0 / 3.0).abs() < 1e-12, "{ratio}");
        assert!(p.normal.dot(c) > p.normal.dot(l), "nearer the camera");
    }

    #[test]
    fn chapter_6_says_d_dot_n_is_minus_0_6() {
        // d = (0.8, −0.6), N = (0, 1): d·N = −0.6.
        let svg = drawn("ch06/mirror");
        assert!(has_label(&svg, "d·N = −0.6"), "{:?}", labels(&svg));
    }

    #[test]
    fn chapter_7_marks_the_sag_at_100_and_keys_each_row_as_the_caption_says() {
        // The caption: "the sag … 0.56 at a distance of 100"; rows 100 and 101 meet
        // the true plane but pass over the fake floor, row 102 meets both.
        let svg = drawn("ch07/sag");
        assert!(has_label(&svg, "0.56 lower at 100"), "{:?}", labels(&svg));
        let chapter = std::fs::read_to_string(root().join("chapters/07-plane.md")).unwrap();
        assert!(chapter.contains("0.56 at a distance of 100"));
        let all = labels(&svg);
        let key = |row: u32| {
            all.iter()
                .find(|l| l.starts_with(&format!("row {row}: ")))
                .unwrap_or_else(|| panic!("row {row}: {all:?}"))
                .clone()
        };
        for row in [100, 101] {
            let line = key(row);
            assert!(
                line.starts_with(&format!("row {row}: the true plane at "))
                    && line.ends_with(", over the fake floor"),
                "{line}"
            );
        }
        assert!(
            key(102).starts_with("row 102: the fake floor at "),
            "{}",
            key(102)
        );
        assert!(key(102).contains(", the true plane at "), "{}", key(102));
        assert_eq!(key(99), "row 99: sky over both floors");
    }

    #[test]
    fn chapter_9_float32_numbers_near_b_squared_are_8_apart() {
        // 2²⁶ ≤ 100,040,000 < 2²⁷: float32's 24 bits leave steps of 2³ there, as the
        // chapter's alt text says.
        let svg = drawn("ch09/cancellation");
        assert!(labels(&svg).iter().any(|l| l.starts_with(
            "float32 numbers here are 8 apart: b² rounds to 100,040,000, and 4c is 100,040,000."
        )));
        let chapter = std::fs::read_to_string(root().join("chapters/09-methods.md")).unwrap();
        assert!(chapter.contains("near 100,040,000 float32 numbers are 8 apart"));
    }

    #[test]
    fn chapter_9_bound_the_bounds_panel_passes_over_up_to_the_0_44_the_chapter_quotes() {
        // "A shadow ray that starts h above a sphere passes over it for |L·N| up to
        // about √(2h/r) …: 0.44 on `tiny-far` in float32 (the diagram …)".
        let chapter = std::fs::read_to_string(root().join("chapters/09-methods.md")).unwrap();
        assert!(chapter.contains("0.44 on `tiny-far` in float32 (the\ndiagram"));
        let svg = drawn("ch09/bound");
        let all = labels(&svg);
        let scene_at_left = all.iter().position(|l| l == "--offset scene").unwrap();
        let auto_at_right = all.iter().position(|l| l == "--offset auto").unwrap();
        assert!(scene_at_left < auto_at_right, "{all:?}");
        let reaches: Vec<&String> = all
            .iter()
            .filter(|l| l.starts_with("passes over up to |L·N| = "))
            .collect();
        assert_eq!(reaches.len(), 2, "{all:?}");
        assert_eq!(reaches[1], "passes over up to |L·N| = 0.44");
        // Each panel's reach is about √(2h/r) for its own step: exactly
        // √(2x + x²)/(1 + x) for x = h/r, between √(2x)/(1 + x) and √(2x). The
        // scene-sized step is the larger: it reaches further.
        let p = bound_picture(&scene_at(root(), TINY_FAR).unwrap()).unwrap();
        let r = p.sphere.radius;
        for (h, reach) in p.steps.iter().zip(p.reach) {
            let estimate = (2.0 * h / r).sqrt();
            let below = estimate / (1.0 + h / r);
            assert!(reach < estimate && reach > below, "{h}: {reach} {estimate}");
        }
        assert!(p.steps[0] > p.steps[1] && p.reach[0] > p.reach[1], "{p:?}");
    }

    #[test]
    fn an_arc_turning_clockwise_on_the_page_has_svgs_sweep_flag_1() {
        // From the right (1, 0) to down (0, 1), y down: a quarter turn clockwise on
        // the page, which SVG calls the positive-angle direction, sweep-flag 1; and
        // back the other way, 0.
        let mut svg = Svg::new(100, 100, "arcs");
        svg.arc(
            px(50.0, 50.0),
            10.0,
            px(1.0, 0.0),
            px(0.0, 1.0),
            pen(INK, 1.0),
        );
        svg.arc(
            px(50.0, 50.0),
            10.0,
            px(0.0, 1.0),
            px(1.0, 0.0),
            pen(INK, 1.0),
        );
        let body = svg.finish();
        assert!(
            body.contains(r#"d="M 60 50 A 10 10 0 0 1 50 60""#),
            "{body}"
        );
        assert!(
            body.contains(r#"d="M 50 60 A 10 10 0 0 0 60 50""#),
            "{body}"
        );
    }
}
