//! The pixel loop: the tutorial's pseudocode, run on every pixel in parallel.
//!
//! Every pixel is computed on its own from the scene alone, so the image is the
//! same, byte for byte, whatever the number of threads.

use rayon::prelude::*;

use crate::aov::{FirstHit, Frame, PixelRecord};
use crate::camera::Camera;
use crate::ray::Ray;
use crate::real::{Precision, Real, Vector};
use crate::scene::{nearest_hit, Light, Object, Scene};
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
}

impl From<Stages> for Settings {
    fn from(stages: Stages) -> Settings {
        Settings {
            stages,
            precision: Precision::default(),
            method: Method::default(),
            offset: Offset::default(),
            viewer: Viewer::default(),
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
}

/// The colour a ray brings back and what its first hit left for the buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Traced {
    /// Colour clipped to [0, 1].
    pub colour: Vec3,
    /// The first hit, or `None` if the ray hit nothing.
    pub first: Option<FirstHit>,
}

impl<T: Real> Tracer<T> {
    /// The tracer of `scene` under `settings`, computing in `T` (the settings'
    /// precision is for [`render`] to choose `T`).
    pub fn new(scene: &Scene, settings: &Settings) -> Tracer<T> {
        Tracer {
            stages: settings.stages,
            method: settings.method,
            offset: settings.offset,
            viewer: settings.viewer,
            camera: scene.camera(),
            objects: scene.objects_in_play(settings.stages),
            light: scene.light.cast(),
            max_depth: scene.max_depth,
        }
    }

    // ANCHOR: pixel
    /// The record of pixel (`row`, `col`). With only the `rays` stage on, the colour
    /// shows the ray's direction: each component mapped from [−1, 1] to [0, 1].
    pub fn pixel(&self, row: u32, col: u32) -> PixelRecord {
        let ray = self.camera.primary_ray::<T>(row, col);
        let direction = ray.direction.to_f64();
        if !self.stages.intersection {
            let colour = (direction + Vec3::ONE) * 0.5;
            return PixelRecord::new(direction, colour, None);
        }
        let traced = self.trace(ray);
        PixelRecord::new(direction, traced.colour, traced.first)
    }
    // ANCHOR_END: pixel

    // ANCHOR: trace
    /// Follow a ray through the scene, as the tutorial's final program does.
    pub fn trace(&self, primary: Ray<T>) -> Traced {
        let segments = if self.stages.reflection {
            self.max_depth
        } else {
            1
        };
        let mut colour = T::Vec3::ZERO;
        let mut weight = T::of(1.0);
        let mut ray = primary;
        let mut first = None;
        for segment in 0..segments {
            // The nearest object along the ray; if there is none, the path ends.
            let Some(hit) = nearest_hit(&self.objects, &ray, self.method) else {
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
                let light_distance = self.light.position.distance(point);
                !shadow::in_shadow(
                    &self.objects,
                    shifted,
                    to_light,
                    light_distance,
                    self.method,
                )
            };
            // ANCHOR_END: shadow_test
            if segment == 0 {
                first = Some(FirstHit {
                    depth: hit.t.to_f64(),
                    normal: normal.to_f64(),
                    lit,
                    object: hit.object,
                });
            }
            if !lit {
                break;
            }

            // ANCHOR: shading
            // Blinn-Phong, seen from the camera (on every bounce, as in the tutorial).
            let illumination = if self.stages.blinn_phong {
                let viewer = match self.viewer {
                    Viewer::Camera => T::Vec3::of(self.camera.position),
                    Viewer::RayOrigin => ray.origin,
                };
                let to_viewer = (viewer - point).normalize();
                blinn_phong::illuminate(&object.material, &self.light, normal, to_light, to_viewer)
            } else {
                object.material.diffuse
            };
            // ANCHOR_END: shading
            // ANCHOR: accumulate
            // Reflection: add this segment's light, weighted, and bounce.
            colour += illumination * weight;
            weight = weight * object.material.reflection;
            ray = reflection::reflected_ray(shifted, &ray, normal);
        }
        // The pixel's colour: the sum, clipped to what a screen can show.
        Traced {
            colour: colour.clamp01().to_f64(),
            first,
        }
        // ANCHOR_END: accumulate
    }
    // ANCHOR_END: trace
}

// ANCHOR: render
/// Render `scene` under `settings`. `progress(1)` is called, from any thread, each
/// time a row is finished.
pub fn render(scene: &Scene, settings: &Settings, progress: &(dyn Fn(u64) + Sync)) -> Frame {
    match settings.precision {
        Precision::F32 => render_in::<f32>(scene, settings, progress),
        Precision::F64 => render_in::<f64>(scene, settings, progress),
    }
}

/// [`render`], computing in `T`.
pub fn render_in<T: Real>(
    scene: &Scene,
    settings: &Settings,
    progress: &(dyn Fn(u64) + Sync),
) -> Frame {
    let tracer = Tracer::<T>::new(scene, settings);
    let width = scene.width as usize;
    let mut pixels =
        vec![PixelRecord::new(Vec3::ZERO, Vec3::ZERO, None); width * scene.height as usize];
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, line)| {
            for (col, pixel) in line.iter_mut().enumerate() {
                *pixel = tracer.pixel(row as u32, col as u32);
            }
            progress(1);
        });
    Frame {
        width: scene.width,
        height: scene.height,
        has_surface_buffers: settings.stages.intersection,
        pixels,
    }
}
// ANCHOR_END: render
