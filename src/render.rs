//! The pixel loop: the tutorial's pseudocode, run on every pixel in parallel.
//!
//! Every pixel is computed on its own from the scene alone, so the image is the
//! same, byte for byte, whatever the number of threads.

use rayon::prelude::*;

use crate::accel::{Accel, TileMasks, BVH_FROM, EVERY};
use crate::aov::{FirstHit, Frame, PixelRecord};
use crate::bvh::Bvh;
use crate::camera::Camera;
use crate::lanes::WIDTH;
use crate::packet::{Packed, BATCH};
use crate::ray::Ray;
use crate::real::{Precision, Real, Vector};
use crate::scene::{consider, nearest_hit, Hit, Light, Object, Role, Scene};
use crate::shade::blinn_phong::{self, Viewer};
use crate::shade::reflection;
use crate::shade::shadow::{self, Offset};
use crate::sphere::Method;
use crate::stages::Stages;
use crate::Vec3;

/// How to render: the stages, and the choices of method that the book compares.
/// `Settings::from(stages)` gives raystep's defaults; [`Settings::tutorial`] the
/// tutorial's own rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Which stages are on.
    pub stages: Stages,
    /// The precision of every computation (`--precision`; default f64).
    pub precision: Precision,
    /// How rays meet spheres (`--intersect`; default stable, tutorial naive).
    pub method: Method,
    /// How far new rays start from a hit point (`--offset`; default auto, tutorial
    /// `fixed:1e-5`).
    pub offset: Offset,
    /// Who views the highlight on a bounce (`--viewer`; default and tutorial: the camera).
    pub viewer: Viewer,
    /// How the nearest hit is searched for (`--accel`; never changes a pixel).
    pub accel: Accel,
    /// Samples per pixel, a square number (`--spp`; default and tutorial: 1).
    pub spp: u32,
    /// End a reflection path once what is left of it cannot move a channel by half
    /// an 8-bit step, so a pixel by at most one level (`--early-stop`; default on,
    /// tutorial off).
    pub early_stop: bool,
    /// Trace four neighbouring pixels at once in SIMD lanes (`--packets`; never
    /// changes a pixel; default on).
    pub packets: bool,
    /// Where the processor has AVX, run the packet tracer compiled for it: four
    /// float64 lanes to a register instead of two (`--avx`; never changes a
    /// pixel; default on).
    pub avx: bool,
}

impl From<Stages> for Settings {
    fn from(stages: Stages) -> Settings {
        Settings {
            stages,
            precision: Precision::default(),
            method: Method::default(),
            offset: Offset::default(),
            viewer: Viewer::default(),
            accel: Accel::default(),
            spp: 1,
            early_stop: true,
            packets: true,
            avx: true,
        }
    }
}

impl Settings {
    /// The tutorial's program exactly: float64, the textbook quadratic, the fixed
    /// 1e-5 step, the camera as the viewer.
    pub fn tutorial(stages: Stages) -> Settings {
        Settings {
            stages,
            precision: Precision::F64,
            method: Method::Naive,
            offset: Offset::TUTORIAL,
            viewer: Viewer::Camera,
            accel: Accel::default(),
            spp: 1,
            early_stop: false,
            packets: true,
            avx: true,
        }
    }
}

/// What the render needs to follow one ray, in precision `T`: the scene reduced to
/// what the enabled stages use.
pub struct Tracer<T: Real = f64> {
    /// The stages that are on.
    pub stages: Stages,
    /// How rays meet spheres.
    pub method: Method,
    /// How far new rays start from a hit point.
    pub offset: Offset,
    /// Who views the highlight on a bounce.
    pub viewer: Viewer,
    /// The camera: where primary rays start, and the viewer of Blinn-Phong.
    pub camera: Camera,
    /// The objects in play under `stages`.
    pub objects: Vec<Object<T>>,
    /// The point light.
    pub light: Light<T>,
    /// Most segments of a path, when the `reflection` stage is on.
    pub max_depth: u32,
    /// Samples per pixel (a square number).
    pub spp: u32,
    /// For each tile of the image, the objects its primary rays can hit.
    pub masks: TileMasks,
    /// The hierarchy over the spheres, for scenes with many of them.
    pub bvh: Option<Bvh>,
    /// With early stop on, `reach[k]`: the most that `k` more segments of weight 1
    /// can add to a channel; empty with early stop off.
    pub reach: Vec<f64>,
    /// Trace four pixels at once ([`Settings::packets`]; without a BVH only for
    /// up to [`crate::packet::MAX_OBJECTS`] objects).
    pub packets: bool,
    /// The objects as the packet tracer reads them; empty without packets or with
    /// a BVH.
    pub packed: Vec<Packed<T>>,
    /// Run the packet tracer's AVX build ([`Settings::avx`], and the processor
    /// has AVX).
    pub avx: bool,
    /// The screen's `x` at each column, for the packet tracer's primary rays
    /// (empty without packets).
    pub columns: Vec<T>,
}

/// How a frame's pixels were traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Packets {
    /// One ray at a time (`--packets off`, or too many objects for the masks).
    Off,
    /// Four at a time, the build for any processor (two float64 lanes to a
    /// register on x86-64: SSE2).
    Baseline,
    /// Four at a time, the AVX build (four float64 lanes to a register).
    Avx,
}

impl Packets {
    /// `"off"`, `"baseline"` or `"avx"`.
    pub fn name(self) -> &'static str {
        match self {
            Packets::Off => "off",
            Packets::Baseline => "baseline",
            Packets::Avx => "avx",
        }
    }
}

/// Half an 8-bit step: a path whose remaining segments cannot add this much to
/// any channel is ended early (`--early-stop`).
pub const HALF_STEP: f64 = 0.5 / 255.0;

/// The colour a ray brings back and what its first hit left for the buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traced {
    /// Colour clipped to [0, 1].
    pub colour: Vec3,
    /// The first hit, or `None` if the ray hit nothing.
    pub first: Option<FirstHit>,
    /// The rays this path traced.
    pub rays: Rays,
}

/// Rays traced, by kind: what `raystep bench` counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rays {
    /// Rays from the camera (one per pixel and sample).
    pub primary: u64,
    /// Rays from a hit point towards the light.
    pub shadow: u64,
    /// Rays from a hit point in the mirrored direction.
    pub reflection: u64,
}

impl Rays {
    /// Every ray, whatever its kind.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflection
    }
}

impl std::ops::AddAssign for Rays {
    fn add_assign(&mut self, other: Rays) {
        self.primary += other.primary;
        self.shadow += other.shadow;
        self.reflection += other.reflection;
    }
}

impl<T: Real> Tracer<T> {
    /// The tracer of `scene` under `settings`, computing in `T` (the settings'
    /// precision is for [`render`] to choose `T`).
    pub fn new(scene: &Scene, settings: &Settings) -> Tracer<T> {
        let camera = scene.camera();
        let objects: Vec<Object<T>> = scene.objects_in_play(settings.stages);
        let spheres = objects.iter().filter(|o| o.role == Role::Sphere).count();
        assert!(
            crate::scene_file::check_spp(settings.spp).is_ok(),
            "spp {} is not a square from 1 to {}",
            settings.spp,
            crate::scene_file::MAX_SPP
        );
        // The textbook quadratic reports false hits far outside spheres (chapter
        // 9); boxes would hide them and change the picture, so it gets no BVH.
        let tree = match settings.accel {
            _ if settings.method == Method::Naive => false,
            Accel::Off => false,
            Accel::Auto => spheres >= BVH_FROM,
            Accel::Bvh => true,
        };
        let bvh = tree.then(|| Bvh::build(&objects, extent(scene)));
        let masks = match settings.accel {
            Accel::Off => TileMasks::none(),
            Accel::Auto | Accel::Bvh => TileMasks::new(&camera, &objects),
        };
        let light: Light<T> = scene.light.cast();
        // Packets search a short list by bit masks, a long one through the BVH.
        let packets =
            settings.packets && (bvh.is_some() || objects.len() <= crate::packet::MAX_OBJECTS);
        let packed = if packets && bvh.is_none() {
            objects.iter().map(|o| Packed::new(o, &light)).collect()
        } else {
            Vec::new()
        };
        let reach = if settings.early_stop {
            reach(&objects, &scene.light, scene.max_depth, settings.stages)
        } else {
            Vec::new()
        };
        Tracer {
            stages: settings.stages,
            method: settings.method,
            offset: settings.offset,
            viewer: settings.viewer,
            objects,
            light,
            max_depth: scene.max_depth,
            spp: settings.spp,
            masks,
            bvh,
            reach,
            packets,
            packed,
            avx: packets && settings.avx && has_avx(),
            columns: match packets {
                true => (0..camera.width)
                    .map(|col| crate::lanes::components::<T>(camera.screen_point::<T>(0, col))[0])
                    .collect(),
                false => Vec::new(),
            },
            camera,
        }
    }

    // ANCHOR: packet_row
    /// The records of row `row`, four pixels at a time ([`Tracer::pixel_packet`]),
    /// into `line`, and the rays they took.
    ///
    /// The packet tracer is compiled twice: for any x86-64 processor (SSE2: two
    /// float64 lanes to a register), and for one with AVX (four). Which one runs
    /// is decided here, from what the processor says it has. Both compute every
    /// lane with the same IEEE operations in the same order, so they give the same
    /// bits; only the number of instructions differs.
    pub fn packet_row(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is true only where the processor has AVX (`has_avx`).
            #[allow(unsafe_code)]
            return unsafe { self.packet_row_avx(row, line) };
        }
        self.packet_row_baseline(row, line)
    }
    // ANCHOR_END: packet_row

    /// [`Tracer::packet_row_in_lanes`] compiled for any processor of the target.
    /// (A function of its own, so that `packet_row`'s frame holds only one of the
    /// two builds' variables: in a debug build, where they are not packed, each
    /// build's frame is about a megabyte.)
    #[inline(never)]
    fn packet_row_baseline(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        self.packet_row_in_lanes(row, line)
    }

    /// [`Tracer::packet_row_in_lanes`] compiled for AVX: everything it calls is
    /// inlined into it, and so compiled for AVX too.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[allow(unsafe_code)]
    unsafe fn packet_row_avx(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        self.packet_row_in_lanes(row, line)
    }

    /// The loop of [`Tracer::packet_row`], for whichever build calls it.
    #[inline(always)]
    fn packet_row_in_lanes(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        let mut rays = Rays::default();
        // The primary rays of a few packets are made before any of them is traced.
        // Each direction waits on a square root and a division; made one after the
        // other they overlap, where made just before its packet each would hold up
        // everything after it.
        for (b, batch) in line.chunks_mut(WIDTH * BATCH).enumerate() {
            let first = (b * WIDTH * BATCH) as u32;
            let mut primary = [self.pixel_rays(row, first); BATCH];
            for (k, packet) in primary.iter_mut().enumerate().skip(1) {
                *packet = self.pixel_rays(row, first + (k * WIDTH) as u32);
            }
            for (k, pixels) in batch.chunks_mut(WIDTH).enumerate() {
                rays += self.pixel_packet(row, first + (k * WIDTH) as u32, primary[k], pixels);
            }
        }
        rays
    }

    /// The nearest object along `ray` among `candidates` (bit `i`: object `i`):
    /// through the BVH if there is one, else the book's plain loop
    /// ([`nearest_hit`]), skipping objects outside `candidates`.
    #[inline]
    pub fn nearest_hit(&self, ray: &Ray<T>, candidates: u64) -> Option<Hit<T>> {
        if let Some(bvh) = &self.bvh {
            return bvh.nearest_hit(&self.objects, ray, self.method);
        }
        if candidates == EVERY {
            return nearest_hit(&self.objects, ray, self.method);
        }
        let mut nearest: Option<Hit<T>> = None;
        let mut left = candidates;
        while left != 0 {
            let index = left.trailing_zeros() as usize;
            left &= left - 1;
            consider(&self.objects, ray, self.method, index, &mut nearest);
        }
        nearest
    }

    /// Does the point `shifted` not see the light? [`shadow::in_shadow`], through
    /// the BVH if there is one.
    #[inline]
    pub fn in_shadow(&self, shifted: T::Vec3, to_light: T::Vec3, light_distance: T) -> bool {
        match &self.bvh {
            Some(bvh) => {
                let ray = Ray {
                    origin: shifted,
                    direction: to_light,
                };
                bvh.blocked(&self.objects, &ray, light_distance, self.method)
            }
            None => shadow::in_shadow(
                &self.objects,
                shifted,
                to_light,
                light_distance,
                self.method,
            ),
        }
    }

    // ANCHOR: pixel
    /// The record of pixel (`row`, `col`) and the rays it took. With only the
    /// `rays` stage on, the colour shows the ray's direction: each component mapped
    /// from [−1, 1] to [0, 1].
    pub fn pixel(&self, row: u32, col: u32) -> (PixelRecord, Rays) {
        let ray = self.camera.primary_ray::<T>(row, col);
        if !self.stages.intersection {
            // Clipped like every colour: rounding can leave a component just past ±1.
            let colour = direction_colour(ray.direction.to_f64()).clamp(Vec3::ZERO, Vec3::ONE);
            let rays = Rays {
                primary: 1,
                ..Rays::default()
            };
            return (PixelRecord::new(colour, None, 0, 1), rays);
        }
        let candidates = self.masks.mask(row, col);
        let traced = self.trace(ray, candidates);
        if self.spp == 1 {
            let record = PixelRecord::new(
                traced.colour,
                traced.first,
                traced.rays.reflection,
                traced.rays.total(),
            );
            return (record, traced.rays);
        }
        // ANCHOR: samples
        // Several samples: the colour is their mean; the buffers keep the centre
        // ray's first hit, so they read the same whatever the sample count.
        let mut rays = traced.rays;
        let mut sum = Vec3::ZERO;
        for sample in 0..self.spp {
            let (y, x) = stratified(row, col, sample, self.spp);
            let ray = self.camera.ray_through::<T>(y, x);
            let traced = self.trace(ray, candidates);
            sum += traced.colour;
            rays += traced.rays;
        }
        let colour = sum / f64::from(self.spp);
        let bounces = traced.rays.reflection;
        (
            PixelRecord::new(colour, traced.first, bounces, rays.total()),
            rays,
        )
        // ANCHOR_END: samples
    }
    // ANCHOR_END: pixel

    // ANCHOR: trace
    /// Follow a ray through the scene, as the tutorial's final program does.
    /// `candidates` holds the objects the primary ray can hit (bit `i` for object
    /// `i`, [`EVERY`] for all); reflected rays search every object.
    pub fn trace(&self, primary: Ray<T>, candidates: u64) -> Traced {
        let segments = if self.stages.reflection {
            self.max_depth
        } else {
            1
        };
        let mut colour = T::Vec3::ZERO;
        let mut weight = T::of(1.0);
        let mut ray = primary;
        let mut first = None;
        let mut rays = Rays {
            primary: 1,
            ..Rays::default()
        };
        for segment in 0..segments {
            if segment > 0 {
                rays.reflection += 1;
            }
            // The nearest object along the ray; if there is none, the path ends.
            let search = if segment == 0 { candidates } else { EVERY };
            let Some(hit) = self.nearest_hit(&ray, search) else {
                break;
            };
            let object = &self.objects[hit.object];
            let point = ray.at(hit.t);
            let normal = object.normal_at(point, &ray);
            let shifted = shadow::step_off(point, normal, object, self.offset);
            let to_light = (self.light.position - shifted).normalize();

            // ANCHOR: shadow_test
            // Shadow: a point that does not see the light ends the path, black.
            let lit = !self.stages.shadow || {
                rays.shadow += 1;
                let light_distance = self.light.position.distance(point);
                !self.in_shadow(shifted, to_light, light_distance)
            };
            // ANCHOR_END: shadow_test

            // ANCHOR: shading
            // Blinn-Phong, seen from the camera (on every bounce, as in the tutorial),
            // at a lit point.
            let terms = (lit && self.stages.blinn_phong).then(|| {
                let viewer = match self.viewer {
                    Viewer::Camera => T::Vec3::of(self.camera.position),
                    Viewer::RayOrigin => ray.origin,
                };
                let to_viewer = (viewer - point).normalize();
                blinn_phong::terms(&object.material, &self.light, normal, to_light, to_viewer)
            });
            // ANCHOR_END: shading
            if segment == 0 {
                first = Some(FirstHit {
                    depth: hit.t.to_f64(),
                    normal: normal.to_f64(),
                    lit,
                    object: hit.object,
                    diffuse: terms.map_or(0.0, |t| t.l_dot_n.to_f64()),
                    specular: terms.map_or(0.0, |t| t.highlight.to_f64()),
                });
            }
            if !lit {
                break;
            }
            // Without Blinn-Phong, the object's flat diffuse colour.
            let illumination = terms.map_or(object.material.diffuse, |t| t.sum());
            // ANCHOR: accumulate
            // Reflection: add this segment's light, weighted, and bounce.
            colour += illumination * weight;
            weight = weight * object.material.reflection;
            ray = reflection::reflected_ray(shifted, &ray, normal);
            // ANCHOR: early_stop
            // Early stop: nothing the rest of the path adds can change the pixel.
            let left = (segments - segment - 1) as usize;
            if self
                .reach
                .get(left)
                .is_some_and(|r| weight.to_f64() * r < HALF_STEP)
            {
                break;
            }
            // ANCHOR_END: early_stop
        }
        // The pixel's colour: the sum, clipped to what a screen can show.
        Traced {
            colour: colour.clamp01().to_f64(),
            first,
            rays,
        }
        // ANCHOR_END: accumulate
    }
    // ANCHOR_END: trace
}

/// The largest coordinate a ray of `scene` can start from or reach: the camera,
/// the light, and every object's size ([`Object::magnitude`]).
pub fn extent(scene: &Scene) -> f64 {
    scene
        .objects
        .iter()
        .map(Object::magnitude)
        .fold(scene.camera.abs().max_element(), f64::max)
        .max(scene.light.position.abs().max_element())
}

// ANCHOR: reach
/// The most that `k` more segments can add to a channel, for `k` from 0 to
/// `max_depth`, when each segment's weight is 1: segment `i` adds at most
/// `ρⁱ · B`, with `B` the largest `|ka·la| + |kd·ld| + |ks·ls|` of any object and
/// channel (every Blinn-Phong factor is at most 1 in size) and `ρ` the largest
/// reflection.
fn reach<T: Real>(
    objects: &[Object<T>],
    light: &Light,
    max_depth: u32,
    stages: Stages,
) -> Vec<f64> {
    let mut most = 0.0f64;
    let mut mirror = 0.0f64;
    for o in objects {
        let m = o.exact().material;
        // Without Blinn-Phong a segment adds its flat diffuse colour.
        let term = if stages.blinn_phong {
            (m.ambient * light.ambient).abs()
                + (m.diffuse * light.diffuse).abs()
                + (m.specular * light.specular).abs()
        } else {
            m.diffuse.abs()
        };
        most = most.max(term.max_element());
        mirror = mirror.max(m.reflection.abs());
    }
    let mut reach = vec![0.0; max_depth as usize + 1];
    for k in 1..reach.len() {
        reach[k] = most + mirror * reach[k - 1];
    }
    reach
}
// ANCHOR_END: reach

// ANCHOR: stratified
/// Sample `sample` of `spp` (a square, n × n) in pixel (`row`, `col`): the centre
/// of one cell of an n × n grid over the pixel, moved by a jitter within the cell.
/// The jitter comes from a hash of the pixel and the sample, so every render gives
/// the same samples. Returns the position in fractional rows and columns.
pub fn stratified(row: u32, col: u32, sample: u32, spp: u32) -> (f64, f64) {
    let n = spp.isqrt();
    let (sy, sx) = (sample / n, sample % n);
    let bits = splitmix64(u64::from(row) << 40 ^ u64::from(col) << 20 ^ u64::from(sample));
    let (jy, jx) = (unit_interval(bits), unit_interval(splitmix64(bits)));
    let n = f64::from(n);
    (
        f64::from(row) - 0.5 + (f64::from(sy) + jy) / n,
        f64::from(col) - 0.5 + (f64::from(sx) + jx) / n,
    )
}
// ANCHOR_END: stratified

/// A number in [0, 1) from the top 53 bits of `bits`: every float64 of the form
/// k / 2⁵³, equally likely.
pub fn unit_interval(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64
}

/// SplitMix64 (Steele, Lea and Flood, 2014): a 64-bit hash whose outputs pass
/// the usual statistical tests; one step of it turns a pixel's coordinates into
/// its jitter.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Does this processor have AVX? (Asked once; false off x86-64.)
pub fn has_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The colour of the `rays` stage: each component of a unit `direction` mapped
/// from [−1, 1] to [0, 1] (before clipping).
pub fn direction_colour(direction: Vec3) -> Vec3 {
    (direction + Vec3::ONE) * 0.5
}

// ANCHOR: render
/// Render `scene` under `settings`. `progress(1)` is called, from any thread, each
/// time a row is finished.
pub fn render(scene: &Scene, settings: &Settings, progress: &(dyn Fn(u64) + Sync)) -> Frame {
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    render_into(scene, settings, &mut frame, progress);
    frame
}

/// [`render`] into a frame of the scene's size that is already allocated (as
/// `raystep bench` does, to time the render alone).
pub fn render_into(
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &(dyn Fn(u64) + Sync),
) {
    match settings.precision {
        Precision::F32 => render_in::<f32>(scene, settings, frame, progress),
        Precision::F64 => render_in::<f64>(scene, settings, frame, progress),
    }
}

/// [`render_into`], computing in `T`: rows in parallel, each pixel on its own.
fn render_in<T: Real>(
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &(dyn Fn(u64) + Sync),
) {
    let tracer = Tracer::<T>::new(scene, settings);
    let width = scene.width as usize;
    assert_eq!(
        frame.pixels.len(),
        width * scene.height as usize,
        "frame size"
    );
    let rays = frame
        .pixels
        .par_chunks_mut(width)
        .enumerate()
        .map(|(row, line)| {
            let mut rays = Rays::default();
            if crate::interrupt::requested() {
                return rays; // Ctrl-C: the rest is skipped, and the frame thrown away
            }
            if tracer.packets {
                rays = tracer.packet_row(row as u32, line);
            } else {
                for (col, pixel) in line.iter_mut().enumerate() {
                    let (record, taken) = tracer.pixel(row as u32, col as u32);
                    *pixel = record;
                    rays += taken;
                }
            }
            progress(1);
            rays
        })
        .reduce(Rays::default, |mut a, b| {
            a += b;
            a
        });
    frame.stages = settings.stages;
    frame.term_colours = tracer
        .objects
        .iter()
        .map(|o| {
            let (m, l) = (o.exact().material, &scene.light);
            [
                m.ambient * l.ambient,
                m.diffuse * l.diffuse,
                m.specular * l.specular,
            ]
        })
        .collect();
    frame.camera = tracer.camera;
    frame.precision = settings.precision;
    frame.rays = rays;
    frame.packets = match (tracer.packets, tracer.avx) {
        (false, _) => Packets::Off,
        (true, false) => Packets::Baseline,
        (true, true) => Packets::Avx,
    };
}
// ANCHOR_END: render
