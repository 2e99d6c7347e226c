//! The book's tracer: the tutorial's pseudocode, one ray at a time, run on every
//! pixel in parallel. This is the engine every picture of the book and every
//! default render comes from (`--engine book`); the fast engine
//! ([`crate::fast`]) gives the same bits four rays at a time and is built on this
//! file, never the other way round.
//!
//! Every pixel is computed on its own from the scene alone, so the image is the
//! same, byte for byte, whatever the number of threads.

use rayon::prelude::*;

use crate::accel::Accel;
use crate::aov::{FirstHit, Frame, Packets, PixelRecord, Rays};
use crate::bvh::Bvh;
use crate::camera::Camera;
use crate::ray::Ray;
use crate::real::{Precision, Real, Vec3Num, Vector};
use crate::samples::stratified;
use crate::scene::{nearest_hit, Hit, Light, Object, Role, Scene};
use crate::shade::blinn_phong::{self, Terms, Viewer};
use crate::shade::reflection;
use crate::shade::shadow::{self, Offset};
use crate::sphere::Method;
use crate::stages::{Engine, Stages};
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
    /// Which tracer renders (`--engine`; never changes a pixel; default: the
    /// book's).
    pub engine: Engine,
    /// Where the processor has AVX, run the fast engine's packet loop compiled for
    /// it: four float64 lanes to a register instead of two (`--avx`; never changes
    /// a pixel; default on).
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
            engine: Engine::default(),
            avx: true,
        }
    }
}

impl Settings {
    /// The tutorial's program exactly: float64, the textbook quadratic, the fixed
    /// 1e-5 step, the camera as the viewer, and no early stop (a path goes on to
    /// `max_depth` segments however little the rest of it can add).
    pub fn tutorial(stages: Stages) -> Settings {
        Settings {
            precision: Precision::F64,
            method: Method::Naive,
            offset: Offset::TUTORIAL,
            viewer: Viewer::Camera,
            early_stop: false,
            ..Settings::from(stages)
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
    /// The hierarchy over the spheres, for scenes with many of them: how
    /// [`Tracer::nearest_hit`] finds the same hit without testing every object.
    pub bvh: Option<Bvh>,
    /// With early stop on, `reach[k]`: the most that `k` more segments of weight 1
    /// can add to a channel; empty with early stop off.
    pub reach: Vec<f64>,
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
}

/// Why a path ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// The segment's ray hit nothing.
    Miss,
    /// The segment's point does not see the light.
    Shadow,
    /// What `left` more segments could add, times the `weight` left, cannot move
    /// the pixel (`--early-stop`); with `left` 0 the path used every segment.
    EarlyStop {
        /// The weight of the next segment.
        weight: f64,
        /// Segments left.
        left: usize,
    },
    /// Every segment was used (early stop off).
    Done,
}

/// Someone watching [`Tracer::trace`] work: the render counts the rays
/// ([`Rays`]), `raystep explain` writes down every number. Every method does
/// nothing unless an observer says otherwise, so watching costs nothing where no
/// one watches (`()`).
pub trait Observer<T: Real> {
    /// A primary ray was made: the centre ray of each pixel, and with samples
    /// (`--spp N`, N > 1) each sample's too.
    fn primary(&mut self, _ray: &Ray<T>) {}
    /// Segment `index` of the path starts: `ray`, whose light counts `weight`.
    fn segment(&mut self, _index: u32, _ray: &Ray<T>, _weight: T) {}
    /// The segment's nearest hit, its point and normal, and the point stepped off
    /// the surface.
    fn hit(&mut self, _hit: &Hit<T>, _point: T::Vec3, _normal: T::Vec3, _shifted: T::Vec3) {}
    /// A shadow ray leaves the stepped-off point towards a light this far from the
    /// hit point.
    fn shadow_ray(&mut self, _ray: &Ray<T>, _light_distance: T) {}
    /// No shadow ray was cast: the light is below the horizon of the sphere the
    /// point lies on (`N·L` = `l_dot_n` < 0), which shadows it.
    fn own_shadow(&mut self, _l_dot_n: T) {}
    /// Blinn-Phong was computed, with `L` and `V`.
    fn shaded(&mut self, _terms: &Terms<T>, _to_light: T::Vec3, _to_viewer: T::Vec3) {}
    /// The segment added `illumination` (before its weight); the path's sum is now
    /// `sum`.
    fn added(&mut self, _illumination: T::Vec3, _sum: T::Vec3) {}
    /// The path ended.
    fn end(&mut self, _why: End) {}
}

/// Watching nothing.
impl<T: Real> Observer<T> for () {}

/// The render's observer: it counts the rays a path traces, for the `rays` and
/// `bounces` buffers, and the paths `trace` followed.
impl<T: Real> Observer<T> for Rays {
    fn primary(&mut self, _ray: &Ray<T>) {
        self.primary += 1;
    }
    fn segment(&mut self, index: u32, _ray: &Ray<T>, _weight: T) {
        self.paths += u64::from(index == 0);
        self.reflection += u64::from(index > 0);
    }
    fn shadow_ray(&mut self, _ray: &Ray<T>, _light_distance: T) {
        self.shadow += 1;
    }
}

impl<T: Real> Tracer<T> {
    /// The tracer of `scene` under `settings`, computing in `T` (the settings'
    /// precision is for [`render`] to choose `T`).
    pub fn new(scene: &Scene, settings: &Settings) -> Tracer<T> {
        let objects: Vec<Object<T>> = scene.objects_in_play(settings.stages);
        let spheres = objects.iter().filter(|o| o.role == Role::Sphere).count();
        // (The textbook quadratic gets no BVH: boxes would hide its false hits.)
        let tree = settings.accel.builds_bvh(spheres, settings.method);
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
            camera: scene.camera(),
            bvh: tree.then(|| Bvh::build(&objects)),
            objects,
            light: scene.light.cast(),
            max_depth: scene.max_depth,
            reach,
        }
    }

    /// The nearest object along `ray`: the book's plain loop ([`nearest_hit`]),
    /// or the same hit found through the BVH if there is one.
    #[inline(always)]
    pub fn nearest_hit(&self, ray: &Ray<T>) -> Option<Hit<T>> {
        match &self.bvh {
            Some(bvh) => bvh.nearest_hit(&self.objects, ray, self.method),
            None => nearest_hit(&self.objects, ray, self.method),
        }
    }

    /// Does the point `shifted` not see the light? [`shadow::in_shadow`], through
    /// the BVH if there is one.
    #[inline(always)]
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

    // `pixel`, `trace` and the searches they call are inlined into the row loop:
    // called, they hand the ray, the hit and the colour over through memory, and
    // each reload waits for the store before it (about a tenth of a frame in
    // `perf record raystep bench --engine book`); inlined, they stay in registers.
    // ANCHOR: pixel
    /// The colour of pixel (`row`, `col`) and its first hit. With only the `rays`
    /// stage on, the colour shows the ray's direction: each component mapped from
    /// [−1, 1] to [0, 1].
    #[inline(always)]
    pub fn pixel(&self, row: u32, col: u32, look: &mut impl Observer<T>) -> Traced {
        let ray = self.camera.primary_ray::<T>(row, col);
        look.primary(&ray);
        if !self.stages.intersection {
            // Clipped like every colour: rounding can leave a component just past ±1.
            let colour = direction_colour(ray.direction.to_f64()).clamp(Vec3::ZERO, Vec3::ONE);
            return Traced {
                colour,
                first: None,
            };
        }
        self.trace(ray, look)
    }
    // ANCHOR_END: pixel

    // ANCHOR: trace
    // ANCHOR: trace_start
    /// Follow a ray through the scene, as the tutorial's final program does,
    /// telling `look` what happens on the way.
    #[inline(always)]
    pub fn trace(&self, primary: Ray<T>, look: &mut impl Observer<T>) -> Traced {
        let segments = if self.stages.reflection {
            self.max_depth
        } else {
            1
        };
        let mut colour = T::Vec3::ZERO;
        let mut weight = T::of(1.0);
        let mut ray = primary;
        let mut first = None;
        let mut end = End::Done;
        for segment in 0..segments {
            look.segment(segment, &ray, weight);
            // The nearest object along the ray; if there is none, the path ends.
            let Some(hit) = self.nearest_hit(&ray) else {
                end = End::Miss;
                break;
            };
            let object = &self.objects[hit.object];
            let point = ray.at(hit.t);
            let normal = object.normal_at(point, &ray);
            let shifted = shadow::step_off(point, normal, object, self.offset);
            let to_light = (self.light.position - shifted).normalize();
            look.hit(&hit, point, normal, shifted);
            // ANCHOR_END: trace_start

            // ANCHOR: shadow_test
            // Shadow: a point that does not see the light ends the path, black.
            let lit = if !self.stages.shadow {
                true
            } else if shadow::own_shadow(object, normal, to_light, self.offset) {
                // Its own sphere hides the light: no ray to ask (chapter 9).
                look.own_shadow(normal.dot(to_light));
                false
            } else {
                let light_distance = self.light.position.distance(point);
                look.shadow_ray(&Ray::new(shifted, to_light), light_distance);
                !self.in_shadow(shifted, to_light, light_distance)
            };
            // ANCHOR_END: shadow_test

            // ANCHOR: shading
            // Blinn-Phong at a lit point, seen from the viewer: by default the camera,
            // on every bounce, as in the tutorial.
            let terms = (lit && self.stages.blinn_phong).then(|| {
                let viewer = match self.viewer {
                    Viewer::Camera => T::Vec3::of(self.camera.position),
                    Viewer::RayOrigin => ray.origin,
                };
                let to_viewer = (viewer - point).normalize();
                let terms =
                    blinn_phong::terms(&object.material, &self.light, normal, to_light, to_viewer);
                look.shaded(&terms, to_light, to_viewer);
                terms
            });
            // ANCHOR_END: shading
            // ANCHOR: trace_end
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
                end = End::Shadow;
                break;
            }
            // Without Blinn-Phong, the object's flat diffuse colour.
            let illumination = terms.map_or(object.material.diffuse, |t| t.sum());
            // ANCHOR: accumulate
            // Reflection: add this segment's light, weighted, and bounce.
            colour += illumination * weight;
            look.added(illumination, colour);
            weight = weight * object.material.reflection;
            ray = reflection::reflected_ray(shifted, &ray, normal);
            // ANCHOR: early_stop
            // Early stop: nothing the rest of the path adds can change the pixel.
            let left = (segments - segment - 1) as usize;
            if let Some(reach) = self.reach.get(left) {
                if weight.to_f64() * reach < HALF_STEP {
                    let weight = weight.to_f64();
                    end = End::EarlyStop { weight, left };
                    break;
                }
            }
            // ANCHOR_END: early_stop
        }
        look.end(end);
        // The pixel's colour: the sum, clipped to what a screen can show.
        Traced {
            colour: colour.clamp01().to_f64(),
            first,
        }
        // ANCHOR_END: accumulate
    }
    // ANCHOR_END: trace_end
    // ANCHOR_END: trace
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

/// The colour of the `rays` stage: each component of a unit `direction` mapped
/// from [−1, 1] to [0, 1] (before clipping).
pub fn direction_colour(direction: Vec3) -> Vec3 {
    (direction + Vec3::ONE) * 0.5
}

/// Render `scene` under `settings` with the book's tracer. `progress(1)` is
/// called, from any thread, each time a row is finished.
pub fn render(scene: &Scene, settings: &Settings, progress: &dyn Progress) -> Frame {
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    render_into(scene, settings, &mut frame, progress);
    frame
}

/// Who follows a render row by row: told of each row finished, and asked before
/// each row is started whether the render is still wanted. Any `Fn(u64)` is one
/// (called with 1 per row, never cancelling); `raystep serve` passes one that a
/// newer request cancels.
pub trait Progress: Sync {
    /// A row is finished.
    fn row_done(&self);
    /// Start no more rows: the frame will be thrown away.
    fn cancelled(&self) -> bool {
        false
    }
    /// The engine is set up (its objects converted, its tree built): the rows
    /// start now. (`raystep bench` times the rows apart from the set-up.)
    fn rows_begin(&self) {}
    /// The last row is finished.
    fn rows_end(&self) {}
}

impl<F: Fn(u64) + Sync> Progress for F {
    fn row_done(&self) {
        self(1)
    }
}

// ANCHOR: render
/// [`render`] into a frame of the scene's size that is already allocated (as
/// `raystep bench` does, to time the render alone).
pub fn render_into(scene: &Scene, settings: &Settings, frame: &mut Frame, progress: &dyn Progress) {
    match settings.precision {
        Precision::F32 => render_in::<f32>(scene, settings, frame, progress),
        Precision::F64 => render_in::<f64>(scene, settings, frame, progress),
    }
}
// ANCHOR_END: render

/// [`render_into`], computing in `T`: rows in parallel, each pixel on its own.
fn render_in<T: Real>(
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &dyn Progress,
) {
    let tracer = &Tracer::<T>::new(scene, settings);
    let width = tracer.camera.width as usize;
    assert_eq!(frame.pixels.len(), width * tracer.camera.height as usize);
    let rays = in_rows(frame, width, progress, |row, line| {
        book_row(tracer, settings.spp, row, line)
    });
    frame.describe(scene, tracer, settings, rays);
}

/// The rows of `frame` (`width` pixels each) traced in parallel by `row`, which
/// fills one row's records and returns the rays they took, telling `progress` of
/// each. After Ctrl-C, or once `progress` is cancelled, the rows left are skipped
/// (and the frame is thrown away). Returns the rays of the whole frame. Both
/// engines render through it.
pub fn in_rows(
    frame: &mut Frame,
    width: usize,
    progress: &dyn Progress,
    row: impl Fn(u32, &mut [PixelRecord]) -> Rays + Sync,
) -> Rays {
    progress.rows_begin();
    // Each row a task of its own (`with_max_len(1)`). Otherwise rayon cuts the
    // rows into a few runs a thread, cuts finer only after a steal, and traces a
    // run once begun to its end: where the costly rows lie together (a layer of
    // 100,000 spheres under an empty sky), one thread was still in a long run at
    // the end while the other waited. Two threads then traced 1.86 times as fast
    // as one (median of seven rounds of `raystep bench`, before and at commit
    // 1400927), and 1.96 with rows as tasks; figure 1, whose costs are spread,
    // is the same either way.
    let rays = frame
        .pixels
        .par_chunks_mut(width)
        .with_max_len(1)
        .enumerate()
        .map(|(r, line)| {
            if crate::interrupt::requested() || progress.cancelled() {
                return Rays::default();
            }
            let rays = row(r as u32, line);
            progress.row_done();
            rays
        })
        .reduce(Rays::default, |mut a, b| {
            a += b;
            a
        });
    progress.rows_end();
    rays
}

// ANCHOR: row
/// The records of row `row` into `line`, pixel by pixel, and the rays they took.
pub fn book_row<T: Real>(tracer: &Tracer<T>, spp: u32, row: u32, line: &mut [PixelRecord]) -> Rays {
    let mut rays = Rays::default();
    for (col, out) in line.iter_mut().enumerate() {
        let col = col as u32;
        let mut path = Rays::default();
        let centre = tracer.pixel(row, col, &mut path);
        let bounces = path.reflection;
        // Several samples: the colour is their mean; the buffers keep the centre
        // ray's first hit, so they read the same whatever the sample count.
        let colour = if spp > 1 && tracer.stages.intersection {
            samples_mean(tracer, row, col, spp, &mut path)
        } else {
            centre.colour
        };
        *out = PixelRecord::new(colour, centre.first, bounces, path.total());
        rays += path;
    }
    rays
}
// ANCHOR_END: row

// ANCHOR: samples
/// The mean colour of `spp` stratified samples of pixel (`row`, `col`), each
/// traced as the book traces a primary ray and told to `look`.
pub fn samples_mean<T: Real>(
    tracer: &Tracer<T>,
    row: u32,
    col: u32,
    spp: u32,
    look: &mut impl Observer<T>,
) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for sample in 0..spp {
        let (y, x) = stratified(row, col, sample, spp);
        let ray = tracer.camera.ray_through::<T>(y, x);
        look.primary(&ray);
        sum += tracer.trace(ray, look).colour;
    }
    sum / f64::from(spp)
}
// ANCHOR_END: samples

impl Frame {
    /// Fill in what a frame says of how it was made, once `tracer` has traced the
    /// pixels of `scene` and they took `rays`.
    pub fn describe<T: Real>(
        &mut self,
        scene: &Scene,
        tracer: &Tracer<T>,
        settings: &Settings,
        rays: Rays,
    ) {
        self.stages = settings.stages;
        self.term_colours = tracer
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
        self.camera = tracer.camera;
        self.precision = settings.precision;
        self.rays = rays;
        self.engine = Engine::Book;
        self.packets = Packets::Off;
    }
}
