//! `raystep explain`: the whole story of one pixel, in the tutorial's terms.
//!
//! The story is told by watching the book's own [`Tracer::pixel`] and
//! [`Tracer::trace`] follow the pixel's path: they tell an [`Observer`] each step
//! (the ray, the hit, the shadow ray, Blinn-Phong's terms, what is added, why the
//! path ends), and the observer here writes every number down. So an edit to the
//! book's code changes the story as it changes the render. Beside what the trace
//! reports, the story tests every object against each segment's ray in the plain
//! loop, to show each one's verdict. `tests/explain.rs` checks, pixel by pixel,
//! that the story ends where the render did.

use serde::Serialize;

use crate::aov::Rays;
use crate::io::output::to_byte;
use crate::ray::Ray;
use crate::real::{Real, Vec3Num, Vector};
use crate::render::{direction_colour, End, Observer, Settings, Tracer};
use crate::scene::{nearest_hit, Hit, Object, Role, Scene, Shape};
use crate::shade::blinn_phong::{Terms, Viewer};
use crate::sphere::Method;
use crate::Vec3;

/// Everything that happened to one pixel.
#[derive(Clone, Debug, Serialize)]
pub struct Explanation {
    /// Column.
    pub x: u32,
    /// Row, from the top.
    pub y: u32,
    /// The stages that were on, e.g. `rays+intersection+shadow`.
    pub stages: String,
    /// Precision, intersection method, offset, viewer, early stop and samples per
    /// pixel, in words.
    pub rules: String,
    /// The intersection method, which decides what each sphere's `discriminant`
    /// is: `Δ` or `Δ/4` ([`discriminant_name`]). The JSON leaves it out: `rules`
    /// says it.
    #[serde(skip)]
    pub method: Method,
    /// The pixel's point on the screen rectangle.
    pub screen_point: [f64; 3],
    /// The primary ray: the camera towards the screen point.
    pub primary: RayInfo,
    /// Distance along the primary ray to its first hit; `None` on a miss.
    pub depth: Option<f64>,
    /// `P`, the first hit's point as the `position` buffer holds it: the primary
    /// ray walked the depth the record keeps (float32), in the render's
    /// precision, rounded to float32 (the hit's
    /// `point` is the one the trace computed); `None` on a miss, where the buffer
    /// holds `(0, 0, 0)`.
    pub position: Option<[f64; 3]>,
    /// Each segment of the path: the primary ray, then its reflections.
    pub segments: Vec<Segment>,
    /// Why the path ended.
    pub end: String,
    /// The weighted sum of the segments' light, before clipping.
    pub unclipped: [f64; 3],
    /// The same clipped to [0, 1]: the pixel (with one sample per pixel).
    pub colour: [f64; 3],
    /// With several samples per pixel: their mean, which is the pixel; this story
    /// follows the centre ray, which gives the buffers.
    pub samples: Option<Samples>,
    /// Rays traced by this path: primary, shadow, reflection.
    pub rays: [u64; 3],
}

/// The samples of a pixel rendered with `--spp` above 1.
#[derive(Clone, Debug, Serialize)]
pub struct Samples {
    /// Samples per pixel.
    pub spp: u32,
    /// Their mean colour: the pixel.
    pub colour: [f64; 3],
    /// Rays traced by all of them and the centre ray.
    pub rays: u64,
}

/// A ray, in float64.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RayInfo {
    /// Where it starts.
    pub origin: [f64; 3],
    /// Its unit direction.
    pub direction: [f64; 3],
}

/// One segment of a path: a ray, what it meets, and the light it brings back.
#[derive(Clone, Debug, Serialize)]
pub struct Segment {
    /// 0 for the primary ray, then 1, 2, … for the reflections.
    pub index: u32,
    /// The ray.
    pub ray: RayInfo,
    /// How much of this segment's light reaches the pixel.
    pub weight: f64,
    /// The test of every object against the ray; of a scene of more than
    /// [`LISTED`] objects, only the objects the ray hits.
    pub tests: Vec<ObjectTest>,
    /// Of a scene of more than [`LISTED`] objects, the misses left out of
    /// `tests`, counted by their verdict (in the order of each verdict's first
    /// object); empty otherwise.
    pub unlisted: Vec<Unlisted>,
    /// The nearest object hit, if any.
    pub hit: Option<HitInfo>,
}

/// Scenes of at most this many objects have every object's test told; in
/// larger ones (100,000 generated spheres would take 400,000 lines) the misses
/// are counted by their reason.
pub const LISTED: usize = 64;

/// Misses of one kind left out of a segment's tests.
#[derive(Clone, Debug, Serialize)]
pub struct Unlisted {
    /// Their verdict, e.g. `miss: Δ/4 < 0, the ray passes beside it`.
    pub verdict: String,
    /// How many objects had it.
    pub count: usize,
}

/// The test of one object against one ray.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectTest {
    /// Index among the objects in play.
    pub object: usize,
    /// What the object is, e.g. `sphere, centre (…), radius 0.7`.
    pub what: String,
    /// For a sphere: the discriminant as the method computes it (`Δ = b² − 4c` for
    /// the naive method, `Δ/4 = r² − ‖f + h·d‖²` for the stable one).
    pub discriminant: Option<f64>,
    /// The roots, smaller first, when the discriminant is positive (a plane: its
    /// one crossing).
    pub roots: Vec<f64>,
    /// The distance if the object is hit.
    pub t: Option<f64>,
    /// Hit or miss and why, in words.
    pub verdict: String,
}

/// The nearest hit of a segment and what was computed at it.
#[derive(Clone, Debug, Serialize)]
pub struct HitInfo {
    /// Index of the object hit.
    pub object: usize,
    /// Distance along the ray.
    pub t: f64,
    /// The hit point, `origin + t·direction`.
    pub point: [f64; 3],
    /// The unit normal there.
    pub normal: [f64; 3],
    /// The point moved off the surface, where new rays start.
    pub shifted: [f64; 3],
    /// How far it was moved.
    pub offset: f64,
    /// The shadow ray, when the shadow stage is on and one is cast.
    pub shadow: Option<ShadowInfo>,
    /// `N·L`, where the point lies on a sphere with the light below its horizon
    /// and no shadow ray is cast (the `auto` offset's `own_shadow`).
    pub own_shadow: Option<f64>,
    /// Does the point see the light? (Always, before the shadow stage.)
    pub lit: bool,
    /// Blinn-Phong's terms, when that stage is on and the point is lit.
    pub shading: Option<Shading>,
    /// The light this segment adds before its weight: the three terms' sum, or the
    /// flat diffuse colour without Blinn-Phong; `None` in shadow.
    pub illumination: Option<[f64; 3]>,
    /// The weighted sum of the path so far.
    pub sum: [f64; 3],
}

/// The shadow ray of a hit point.
#[derive(Clone, Debug, Serialize)]
pub struct ShadowInfo {
    /// From the shifted point, towards the light.
    pub ray: RayInfo,
    /// The light's distance, measured from the hit point.
    pub light_distance: f64,
    /// The nearest object the shadow ray meets, and where.
    pub blocker: Option<(usize, f64)>,
}

/// Blinn-Phong at a lit point.
#[derive(Clone, Debug, Serialize)]
pub struct Shading {
    /// L, towards the light.
    pub to_light: [f64; 3],
    /// V, towards the viewer.
    pub to_viewer: [f64; 3],
    /// `L·N`.
    pub l_dot_n: f64,
    /// `N·H`, clamped at 0.
    pub n_dot_h: f64,
    /// The exponent, `shininess / 4`.
    pub exponent: f64,
    /// `(N·H)^exponent`.
    pub highlight: f64,
    /// `ka·la`.
    pub ambient: [f64; 3],
    /// `kd·ld·(L·N)`.
    pub diffuse: [f64; 3],
    /// `ks·ls·(N·H)^exponent`.
    pub specular: [f64; 3],
}

/// The story of pixel (`x`, `y`) of `scene` under `settings`.
pub fn explain(scene: &Scene, settings: &Settings, x: u32, y: u32) -> Explanation {
    match settings.precision {
        crate::real::Precision::F32 => explain_in::<f32>(scene, settings, x, y),
        crate::real::Precision::F64 => explain_in::<f64>(scene, settings, x, y),
    }
}

fn explain_in<T: Real>(scene: &Scene, settings: &Settings, x: u32, y: u32) -> Explanation {
    let tracer = Tracer::<T>::new(scene, settings);
    let (row, col) = (y, x);
    let mut story = Story {
        tracer: &tracer,
        told: Explanation {
            x,
            y,
            stages: settings.stages.to_string(),
            rules: rules(settings),
            method: settings.method,
            screen_point: tracer
                .camera
                .screen_point::<T>(row, col)
                .to_f64()
                .to_array(),
            primary: RayInfo {
                origin: [0.0; 3],
                direction: [0.0; 3],
            },
            depth: None,
            position: None,
            segments: Vec::new(),
            end: String::new(),
            unclipped: [0.0; 3],
            colour: [0.0; 3],
            samples: None,
            rays: [0; 3],
        },
        sum: T::Vec3::ZERO,
        rays: Rays::default(),
    };
    // The book's own pixel, watched: the story is what the render computes.
    let traced = tracer.pixel(row, col, &mut story);
    let Story {
        mut told,
        sum,
        rays,
        ..
    } = story;
    told.colour = traced.colour.to_array();
    told.rays = [rays.primary, rays.shadow, rays.reflection];
    if !settings.stages.intersection {
        told.end = "only the rays stage is on: the colour shows the ray's direction, \
                    each component mapped from [−1, 1] to [0, 1]"
            .into();
        told.unclipped = direction_colour(Vec3::from_array(told.primary.direction)).to_array();
        return told;
    }
    told.unclipped = sum.to_f64().to_array();
    // As `Frame::position` computes it, from the depth the record keeps.
    told.position = told.depth.map(|depth| {
        let ray = tracer.camera.primary_ray::<T>(row, col);
        let at = ray.at(T::of(f64::from(depth as f32)));
        at.to_f64().as_vec3().as_dvec3().to_array()
    });
    if settings.spp > 1 {
        let mut all = rays;
        let mean = crate::render::samples_mean(&tracer, row, col, settings.spp, &mut all);
        told.samples = Some(Samples {
            spp: settings.spp,
            // As the record keeps it: in float32.
            colour: mean.as_vec3().as_dvec3().to_array(),
            rays: all.total(),
        });
    }
    told
}

/// The observer that writes the story down as the book's `trace` goes.
struct Story<'a, T: Real> {
    tracer: &'a Tracer<T>,
    told: Explanation,
    /// The path's sum so far.
    sum: T::Vec3,
    /// The rays the path traced.
    rays: Rays,
}

impl<T: Real> Story<'_, T> {
    /// The hit of the segment being told.
    fn current_hit(&mut self) -> &mut HitInfo {
        let segment = self.told.segments.last_mut();
        let hit = segment.and_then(|s| s.hit.as_mut());
        hit.expect("the book's trace reports a hit before what it computes there")
    }
}

impl<T: Real> Observer<T> for Story<'_, T> {
    fn primary(&mut self, ray: &Ray<T>) {
        Observer::<T>::primary(&mut self.rays, ray);
        self.told.primary = info(ray);
    }

    fn segment(&mut self, index: u32, ray: &Ray<T>, weight: T) {
        self.rays.segment(index, ray, weight);
        let (objects, method) = (&self.tracer.objects, self.tracer.method);
        let (mut tests, mut unlisted) = (Vec::new(), Vec::<Unlisted>::new());
        let every = objects.len() <= LISTED;
        for (i, object) in objects.iter().enumerate() {
            let mut test = judge(i, object, ray, method);
            if every || test.t.is_some() {
                test.what = what(object);
                tests.push(test);
                continue;
            }
            match unlisted.iter_mut().find(|u| u.verdict == test.verdict) {
                Some(u) => u.count += 1,
                None => unlisted.push(Unlisted {
                    verdict: test.verdict,
                    count: 1,
                }),
            }
        }
        self.told.segments.push(Segment {
            index,
            ray: info(ray),
            weight: weight.to_f64(),
            tests,
            unlisted,
            hit: None,
        });
    }

    fn hit(&mut self, hit: &Hit<T>, point: T::Vec3, normal: T::Vec3, shifted: T::Vec3) {
        if self.told.segments.len() == 1 {
            self.told.depth = Some(hit.t.to_f64());
        }
        let sum = self.sum.to_f64().to_array();
        let segment = self.told.segments.last_mut().expect("a segment has begun");
        segment.hit = Some(HitInfo {
            object: hit.object,
            t: hit.t.to_f64(),
            point: point.to_f64().to_array(),
            normal: normal.to_f64().to_array(),
            shifted: shifted.to_f64().to_array(),
            offset: (shifted - point).length().to_f64(),
            shadow: None,
            own_shadow: None,
            lit: true,
            shading: None,
            illumination: None,
            sum,
        });
    }

    fn shadow_ray(&mut self, ray: &Ray<T>, light_distance: T) {
        self.rays.shadow_ray(ray, light_distance);
        // The nearest blocker, to tell where it stands (the render asks only
        // whether there is one before the light).
        let blocker = nearest_hit(&self.tracer.objects, ray, self.tracer.method);
        let light_distance = light_distance.to_f64();
        let hit = self.current_hit();
        hit.lit = blocker.is_none_or(|b| b.t.to_f64() >= light_distance);
        hit.shadow = Some(ShadowInfo {
            ray: info(ray),
            light_distance,
            blocker: blocker.map(|b| (b.object, b.t.to_f64())),
        });
    }

    fn own_shadow(&mut self, l_dot_n: T) {
        let hit = self.current_hit();
        hit.lit = false;
        hit.own_shadow = Some(l_dot_n.to_f64());
    }

    fn shaded(&mut self, t: &Terms<T>, to_light: T::Vec3, to_viewer: T::Vec3) {
        let object = self.current_hit().object;
        let shininess = self.tracer.objects[object].material.shininess;
        self.current_hit().shading = Some(Shading {
            to_light: to_light.to_f64().to_array(),
            to_viewer: to_viewer.to_f64().to_array(),
            l_dot_n: t.l_dot_n.to_f64(),
            n_dot_h: t.n_dot_h.to_f64(),
            exponent: (shininess / T::of(4.0)).to_f64(),
            highlight: t.highlight.to_f64(),
            ambient: t.ambient.to_f64().to_array(),
            diffuse: t.diffuse.to_f64().to_array(),
            specular: t.specular.to_f64().to_array(),
        });
    }

    fn added(&mut self, illumination: T::Vec3, sum: T::Vec3) {
        self.sum = sum;
        let hit = self.current_hit();
        hit.illumination = Some(illumination.to_f64().to_array());
        hit.sum = sum.to_f64().to_array();
    }

    fn end(&mut self, why: End) {
        let index = self.told.segments.len().saturating_sub(1);
        self.told.end = match why {
            End::Miss if index == 0 => {
                "the primary ray hits nothing: the pixel is black (the tutorial has no sky colour)"
                    .into()
            }
            End::Miss => format!("reflection {index} hits nothing: the sky adds no light"),
            End::Shadow => {
                self.current_hit().lit = false;
                format!(
                    "the point of segment {index} does not see the light: the path ends there \
                     and adds nothing more (the tutorial's rule)"
                )
            }
            End::EarlyStop { weight, left } if left > 0 => format!(
                "early stop after segment {index}: the weight left, {}, times the most \
                 {left} more segments can add, {}, is below half an 8-bit step",
                num(weight),
                num(self.tracer.reach[left])
            ),
            End::EarlyStop { .. } | End::Done => {
                format!("the path used all {} of its segments", index + 1)
            }
        };
    }
}

/// The test of object `index` against `ray`, with its numbers and verdict, but
/// not yet what the object is (`what` is empty: [`what`] gives it).
fn judge<T: Real>(index: usize, object: &Object<T>, ray: &Ray<T>, method: Method) -> ObjectTest {
    let t = object.intersect(ray, method).map(Real::to_f64);
    match &object.shape {
        Shape::Sphere(s) => {
            let (discriminant, roots) = match method {
                Method::Naive => (s.discriminant_naive(ray), s.roots_naive(ray)),
                Method::Stable => (s.quarter_discriminant(ray), s.roots_stable(ray)),
            };
            let name = discriminant_name(method);
            let d = discriminant.to_f64();
            let roots: Vec<f64> = roots.map_or(Vec::new(), |(a, b)| vec![a.to_f64(), b.to_f64()]);
            let verdict = match (t, roots.as_slice()) {
                (Some(t), _) => format!("hit at t = {}", num(t)),
                (None, []) if d == 0.0 => format!("miss: {name} = 0, the ray only touches it"),
                (None, []) if d < 0.0 => format!("miss: {name} < 0, the ray passes beside it"),
                (None, []) => format!("miss: {name} is not a number"),
                (None, [a, b]) if *a <= 0.0 && *b <= 0.0 => {
                    "miss: both roots negative, the sphere is behind the ray".into()
                }
                (None, _) => "miss: one root negative, the ray starts inside the sphere \
                              (the tutorial needs both roots positive)"
                    .into(),
            };
            ObjectTest {
                object: index,
                what: String::new(),
                discriminant: Some(d),
                roots,
                t,
                verdict,
            }
        }
        Shape::Plane(p) => {
            let facing = ray.direction.dot(p.normal).to_f64();
            let crossing = (p.point - ray.origin).dot(p.normal).to_f64() / facing;
            let verdict = match t {
                Some(t) => format!("hit at t = {}", num(t)),
                None if facing == 0.0 => "miss: the ray runs parallel to the plane".into(),
                None => "miss: the plane is behind the ray".into(),
            };
            ObjectTest {
                object: index,
                what: String::new(),
                discriminant: None,
                roots: if facing == 0.0 {
                    Vec::new()
                } else {
                    vec![crossing]
                },
                t,
                verdict,
            }
        }
    }
}

/// What a sphere's test computes as its discriminant under `method`: the naive
/// method's `Δ = b² − 4c`, or the stable method's `Δ/4 = r² − ‖f + h·d‖²`
/// (chapter 9), which has the same sign.
pub fn discriminant_name(method: Method) -> &'static str {
    match method {
        Method::Naive => "Δ",
        Method::Stable => "Δ/4",
    }
}

/// What `object` is, as a test names it: `sphere, centre (…), radius 0.7`.
fn what<T: Real>(object: &Object<T>) -> String {
    let role = match object.role {
        Role::Sphere => "",
        Role::Floor => " (the floor)",
    };
    match &object.shape {
        Shape::Sphere(s) => format!(
            "sphere{role}, centre {}, radius {}",
            vector(s.center.to_f64()),
            num(s.radius.to_f64())
        ),
        Shape::Plane(p) => format!(
            "plane{role}, through {}, normal {}",
            vector(p.point.to_f64()),
            vector(p.normal.to_f64())
        ),
    }
}

fn info<T: Real>(ray: &Ray<T>) -> RayInfo {
    RayInfo {
        origin: ray.origin.to_f64().to_array(),
        direction: ray.direction.to_f64().to_array(),
    }
}

fn rules(settings: &Settings) -> String {
    format!(
        "precision {}, intersection {}, offset {}, viewer {}, early stop {}, {} sample{} per pixel",
        settings.precision,
        settings.method,
        settings.offset,
        match settings.viewer {
            Viewer::Camera => "camera",
            Viewer::RayOrigin => "ray origin",
        },
        if settings.early_stop { "on" } else { "off" },
        settings.spp,
        if settings.spp == 1 { "" } else { "s" }
    )
}

/// A number for people: 6 significant digits, no trailing zeros.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-4..6).contains(&magnitude) {
        return format!("{x:.5e}");
    }
    let decimals = (5 - magnitude).max(0) as usize;
    let text = format!("{x:.decimals$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

fn vector(v: Vec3) -> String {
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

fn vec3(v: [f64; 3]) -> String {
    vector(Vec3::from_array(v))
}

impl std::fmt::Display for Explanation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "pixel x = {}, y = {} (column, row from the top)",
            self.x, self.y
        )?;
        writeln!(f, "stages: {}", self.stages)?;
        writeln!(f, "rules: {}", self.rules)?;
        writeln!(f)?;
        writeln!(f, "primary ray")?;
        writeln!(f, "  screen point  {}", vec3(self.screen_point))?;
        writeln!(
            f,
            "  origin        {}  (the camera)",
            vec3(self.primary.origin)
        )?;
        writeln!(
            f,
            "  direction     {}  (normalize(screen point − camera))",
            vec3(self.primary.direction)
        )?;
        for s in &self.segments {
            writeln!(f)?;
            if s.index == 0 {
                writeln!(f, "segment 0: the primary ray, weight {}", num(s.weight))?;
            } else {
                writeln!(
                    f,
                    "segment {}: reflection {}, weight {}",
                    s.index,
                    s.index,
                    num(s.weight)
                )?;
                writeln!(
                    f,
                    "  ray from {} along {}",
                    vec3(s.ray.origin),
                    vec3(s.ray.direction)
                )?;
            }
            for t in &s.tests {
                write!(f, "  object {}: {}", t.object, t.what)?;
                if let Some(d) = t.discriminant {
                    let name = discriminant_name(self.method);
                    write!(f, "; discriminant {name} = {}", num(d))?;
                }
                if !t.roots.is_empty() {
                    let roots: Vec<String> = t.roots.iter().map(|&r| num(r)).collect();
                    write!(f, "; roots {}", roots.join(", "))?;
                }
                writeln!(f, "\n    → {}", t.verdict)?;
            }
            for u in &s.unlisted {
                let objects = if u.count == 1 { "object" } else { "objects" };
                writeln!(f, "  {} other {objects}\n    → {}", u.count, u.verdict)?;
            }
            let Some(h) = &s.hit else {
                writeln!(f, "  nearest: nothing")?;
                continue;
            };
            writeln!(f, "  nearest: object {} at t = {}", h.object, num(h.t))?;
            writeln!(f, "  point   {}", vec3(h.point))?;
            if let (0, Some(p)) = (s.index, self.position) {
                writeln!(
                    f,
                    "  position buffer P = {}  (the point again, from the depth in float32)",
                    vec3(p)
                )?;
            }
            writeln!(f, "  normal  {}", vec3(h.normal))?;
            writeln!(
                f,
                "  moved off the surface by {} to {}",
                num(h.offset),
                vec3(h.shifted)
            )?;
            match &h.shadow {
                None => match h.own_shadow {
                    Some(l_dot_n) => writeln!(
                        f,
                        "  the light is below this sphere's horizon (N·L = {})\n    → the sphere \
                         shadows the point itself: in shadow, no shadow ray cast",
                        num(l_dot_n)
                    )?,
                    None => writeln!(f, "  shadow: stage off, the point counts as lit")?,
                },
                Some(sh) => {
                    writeln!(
                        f,
                        "  shadow ray from the moved point along {}; the light is {} away",
                        vec3(sh.ray.direction),
                        num(sh.light_distance)
                    )?;
                    match sh.blocker {
                        None => writeln!(f, "    → nothing in the way: lit")?,
                        Some((o, t)) if t < sh.light_distance => writeln!(
                            f,
                            "    → object {o} at {} < {}: in shadow",
                            num(t),
                            num(sh.light_distance)
                        )?,
                        Some((o, t)) => writeln!(
                            f,
                            "    → object {o} at {}, beyond the light ({}): lit",
                            num(t),
                            num(sh.light_distance)
                        )?,
                    }
                }
            }
            if let Some(b) = &h.shading {
                writeln!(
                    f,
                    "  Blinn-Phong: L = {}, V = {}",
                    vec3(b.to_light),
                    vec3(b.to_viewer)
                )?;
                writeln!(
                    f,
                    "    L·N = {}, N·H = {}, (N·H)^{} = {}",
                    num(b.l_dot_n),
                    num(b.n_dot_h),
                    num(b.exponent),
                    num(b.highlight)
                )?;
                writeln!(f, "    ambient  ka·la             = {}", vec3(b.ambient))?;
                writeln!(f, "    diffuse  kd·ld·(L·N)       = {}", vec3(b.diffuse))?;
                writeln!(
                    f,
                    "    specular ks·ls·(N·H)^{:<5} = {}",
                    num(b.exponent),
                    vec3(b.specular)
                )?;
            }
            match h.illumination {
                Some(c) => writeln!(
                    f,
                    "  adds {} × weight {}; the sum is now {}",
                    vec3(c),
                    num(s.weight),
                    vec3(h.sum)
                )?,
                None => writeln!(f, "  adds nothing (in shadow)")?,
            }
        }
        writeln!(f)?;
        writeln!(f, "end: {}", self.end)?;
        writeln!(
            f,
            "colour: {} → clipped to [0, 1]: {} → 8-bit ({}, {}, {})",
            vec3(self.unclipped),
            vec3(self.colour),
            to_byte(self.colour[0] as f32),
            to_byte(self.colour[1] as f32),
            to_byte(self.colour[2] as f32)
        )?;
        if let Some(s) = &self.samples {
            writeln!(
                f,
                "with {} samples the pixel is their mean, {}; this story followed the centre ray (the buffers' ray)",
                s.spp,
                vec3(s.colour)
            )?;
        }
        writeln!(
            f,
            "rays: {} primary, {} shadow, {} reflected",
            self.rays[0], self.rays[1], self.rays[2]
        )
    }
}
