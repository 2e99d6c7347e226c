//! The yardstick of `raystep bench`: the tutorial's final program ported plainly to
//! Rust, and nothing else.
//!
//! float64, the textbook quadratic, the fixed 1e-5 step, the nearest hit of the
//! shadow ray compared with the light's distance, the camera as the viewer on every
//! bounce, and rayon over pixels. No culling, no early exits, no precomputation: what
//! a careful reader would write from the Python on a first pass. Its image equals
//! raystep's own render under `--tutorial` (a test checks it), so a ratio of their
//! times measures only how the work is done, not what is computed.

use glam::DVec3;
use rayon::prelude::*;

use crate::scene::{Scene, Shape};

/// One sphere of the port: the tutorial's dictionary of an object.
struct Ball {
    center: DVec3,
    radius: f64,
    ambient: DVec3,
    diffuse: DVec3,
    specular: DVec3,
    shininess: f64,
    reflection: f64,
}

/// The port's scene: every object is a sphere, as in the tutorial.
pub struct Yardstick {
    balls: Vec<Ball>,
    camera: DVec3,
    light: [DVec3; 4],
    xs: Vec<f64>,
    ys: Vec<f64>,
    max_depth: u32,
}

impl Yardstick {
    /// The port of `scene`, or `None` if the scene has a true plane (the tutorial
    /// knows only spheres).
    pub fn new(scene: &Scene) -> Option<Yardstick> {
        let mut balls = Vec::with_capacity(scene.objects.len());
        for o in &scene.objects {
            let Shape::Sphere(s) = o.shape else {
                return None;
            };
            let m = &o.material;
            balls.push(Ball {
                center: s.center,
                radius: s.radius,
                ambient: m.ambient,
                diffuse: m.diffuse,
                specular: m.specular,
                shininess: m.shininess,
                reflection: m.reflection,
            });
        }
        let camera = scene.camera();
        let s = camera.screen;
        // numpy's linspace: a + i·step, and the last value exactly b.
        let linspace = |a: f64, b: f64, n: u32| -> Vec<f64> {
            if n < 2 {
                return vec![a];
            }
            let step = (b - a) / f64::from(n - 1);
            let mut values: Vec<f64> = (0..n).map(|i| a + f64::from(i) * step).collect();
            values[n as usize - 1] = b;
            values
        };
        let l = &scene.light;
        Some(Yardstick {
            balls,
            camera: scene.camera,
            light: [l.position, l.ambient, l.diffuse, l.specular],
            xs: linspace(s.left, s.right, scene.width),
            ys: linspace(s.top, s.bottom, scene.height),
            max_depth: scene.max_depth,
        })
    }

    /// The image, row by row from the top, each pixel clipped to [0, 1].
    pub fn render(&self) -> Vec<DVec3> {
        let (mut image, mut rays) = (Vec::new(), Vec::new());
        self.render_into(&mut image, &mut rays);
        image
    }

    /// [`Yardstick::render`] into `image`, and the rays each pixel traced into
    /// `rays`, both resized to fit: rayon over pixels. Returns the frame's rays,
    /// summed after the frame (a counter shared by the threads would make them
    /// wait on each other).
    pub fn render_into(&self, image: &mut Vec<DVec3>, rays: &mut Vec<u32>) -> u64 {
        let width = self.xs.len();
        let pixels = width * self.ys.len();
        image.resize(pixels, DVec3::ZERO);
        rays.resize(pixels, 0);
        image
            .par_iter_mut()
            .zip(rays.par_iter_mut())
            .enumerate()
            .for_each(|(i, (pixel, rays))| {
                (*pixel, *rays) = self.pixel(self.ys[i / width], self.xs[i % width]);
            });
        rays.iter().map(|&r| u64::from(r)).sum()
    }

    fn sphere_intersect(
        center: DVec3,
        radius: f64,
        origin: DVec3,
        direction: DVec3,
    ) -> Option<f64> {
        let b = 2.0 * direction.dot(origin - center);
        let c = (origin - center).length_squared() - radius * radius;
        let delta = b * b - 4.0 * c;
        if delta > 0.0 {
            let t1 = (-b + delta.sqrt()) / 2.0;
            let t2 = (-b - delta.sqrt()) / 2.0;
            if t1 > 0.0 && t2 > 0.0 {
                return Some(t1.min(t2));
            }
        }
        None
    }

    fn nearest_intersected_object(&self, origin: DVec3, direction: DVec3) -> Option<(usize, f64)> {
        let mut nearest: Option<(usize, f64)> = None;
        for (i, b) in self.balls.iter().enumerate() {
            if let Some(t) = Self::sphere_intersect(b.center, b.radius, origin, direction) {
                if nearest.is_none_or(|(_, n)| t < n) {
                    nearest = Some((i, t));
                }
            }
        }
        nearest
    }

    /// The colour of the pixel looking at screen point (`x`, `y`), and the rays
    /// it traced.
    fn pixel(&self, y: f64, x: f64) -> (DVec3, u32) {
        let [light, la, ld, ls] = self.light;
        let mut rays = 1;
        let mut origin = self.camera;
        let mut direction = (DVec3::new(x, y, 0.0) - origin).normalize();
        let mut colour = DVec3::ZERO;
        let mut reflection = 1.0;
        for depth in 0..self.max_depth {
            rays += u32::from(depth > 0);
            let Some((i, distance)) = self.nearest_intersected_object(origin, direction) else {
                break;
            };
            let ball = &self.balls[i];
            let intersection = origin + distance * direction;
            let normal = (intersection - ball.center).normalize();
            let shifted = intersection + 1e-5 * normal;
            let to_light = (light - shifted).normalize();
            let light_distance = (light - intersection).length();
            rays += 1;
            let is_shadowed = self
                .nearest_intersected_object(shifted, to_light)
                .is_some_and(|(_, t)| t < light_distance);
            if is_shadowed {
                break;
            }
            let mut illumination = ball.ambient * la;
            illumination += ball.diffuse * ld * to_light.dot(normal);
            let to_camera = (self.camera - intersection).normalize();
            let h = (to_light + to_camera).normalize();
            illumination += ball.specular * ls * normal.dot(h).max(0.0).powf(ball.shininess / 4.0);
            colour += reflection * illumination;
            reflection *= ball.reflection;
            origin = shifted;
            direction = direction - 2.0 * direction.dot(normal) * normal;
        }
        (colour.clamp(DVec3::ZERO, DVec3::ONE), rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The port's pixel centres are numpy's `linspace`: the last one is the
    /// screen's edge exactly, even where `a + (n - 1) · step` rounds past it
    /// (`-1 + 98 · (2 / 98)` is not 1 in float64, nor is the height's sum at 49).
    #[test]
    fn the_pixel_centres_end_exactly_at_the_screens_edges() {
        assert_ne!(-1.0 + 98.0 * (2.0 / 98.0), 1.0);
        let mut scene = crate::io::scene_file::seed();
        (scene.width, scene.height) = (99, 49);
        let port = Yardstick::new(&scene).unwrap();
        let top = 1.0 / (99.0 / 49.0);
        assert_eq!(port.xs.len(), 99);
        assert_eq!((port.xs[0], port.xs[98]), (-1.0, 1.0));
        assert_eq!(port.xs[1], -1.0 + 2.0 / 98.0);
        assert_eq!(port.ys.len(), 49);
        assert_eq!((port.ys[0], port.ys[48]), (top, -top));
    }
}
