//! `raystep generate spheres`: scenes of many spheres, to see how the cost grows
//! with the scene.
//!
//! N spheres rest on the tutorial's floor, spread evenly at random over a patch of
//! 10 × 12 units in front of the camera; their radius shrinks as 1/√N so that the
//! patch looks about as full at every N. Colours and mirror weights are random.
//! The same count and seed give the same scene, byte for byte: the numbers come
//! from SplitMix64 and are rounded to 5 decimals before use, so the TOML text
//! holds them exactly.

use std::fmt::Write;

use crate::samples::{splitmix64, unit_interval};
use crate::scene::{Material, Object, Role, Scene, Shape};
use crate::sphere::Sphere;
use crate::Vec3;

/// A sphere of a generated scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Centre.
    pub center: [f64; 3],
    /// Radius.
    pub radius: f64,
    /// Ambient colour: a tenth of the diffuse one.
    pub ambient: [f64; 3],
    /// Diffuse colour.
    pub diffuse: [f64; 3],
    /// Mirror weight.
    pub reflection: f64,
}

/// Height of the floor's top (the tutorial's floor sphere: −9000 + 8999.3).
const FLOOR: f64 = -0.7;

/// N spheres from `seed`.
pub fn spheres(count: usize, seed: u64) -> Vec<Ball> {
    let mut state = splitmix64(seed);
    let mut next = move || {
        state = splitmix64(state);
        unit_interval(state)
    };
    let round = |x: f64| (x * 1e5).round() / 1e5;
    let (width, depth) = (10.0, 12.0);
    let spacing = (width * depth / count.max(1) as f64).sqrt();
    let largest = (0.3 * spacing).clamp(0.002, 0.5);
    (0..count)
        .map(|_| {
            let radius = round(largest * (0.6 + 0.4 * next())).max(1e-5);
            let x = round((next() - 0.5) * width);
            let z = round(-1.0 - next() * depth);
            let diffuse = [(); 3].map(|_| round(0.2 + 0.7 * next()));
            Ball {
                center: [x, round(FLOOR + radius), z],
                radius,
                ambient: diffuse.map(|c| (c * 1e6).round() / 1e7),
                diffuse,
                reflection: round(0.5 * next()),
            }
        })
        .collect()
}

/// The scene file of N spheres from `seed`, at 1920 × 1080.
pub fn spheres_toml(count: usize, seed: u64) -> String {
    let mut text = String::with_capacity(200 + count * 120);
    let _ = writeln!(
        text,
        "# {count} spheres over the floor: raystep generate spheres --count {count} --seed {seed}\n\
         \n[image]\nwidth = 1920\nheight = 1080\n\n[camera]\nposition = [0, 0.2, 1]\n\n\
         [light]\nposition = [5, 5, 5]\n\n[render]\nmax_depth = 3\n\n\
         [[plane]]\nsphere = {{ center = [0, -9000, 0], radius = 8999.3 }}\n\
         ambient = [0.1, 0.1, 0.1]\ndiffuse = [0.6, 0.6, 0.6]\n"
    );
    for b in spheres(count, seed) {
        let [x, y, z] = b.center;
        let [ar, ag, ab] = b.ambient;
        let [dr, dg, db] = b.diffuse;
        let _ = writeln!(
            text,
            "[[sphere]]\ncenter = [{x}, {y}, {z}]\nradius = {}\nambient = [{ar}, {ag}, {ab}]\n\
             diffuse = [{dr}, {dg}, {db}]\nreflection = {}",
            b.radius, b.reflection
        );
    }
    text
}

/// The scene of [`spheres_toml`], built directly (a million spheres would make a
/// scene file of 150 MB, beyond what the loader reads).
pub fn scene(count: usize, seed: u64) -> Scene {
    let mut scene = crate::io::scene_file::parse(&spheres_toml(0, seed), "generated")
        .expect("the generated header is a valid scene");
    let floor = scene.objects.pop().expect("the header has the floor");
    scene.objects = spheres(count, seed)
        .into_iter()
        .map(|b| Object {
            shape: Shape::Sphere(Sphere {
                center: Vec3::from(b.center),
                radius: b.radius,
            }),
            material: Material {
                ambient: Vec3::from(b.ambient),
                diffuse: Vec3::from(b.diffuse),
                specular: floor.material.specular,
                shininess: floor.material.shininess,
                reflection: b.reflection,
            },
            role: Role::Sphere,
        })
        .collect();
    scene.objects.push(floor);
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_spheres_and_another_seed_others() {
        assert_eq!(spheres(100, 7), spheres(100, 7));
        assert_ne!(spheres(100, 7), spheres(100, 8));
    }

    #[test]
    fn the_scene_file_and_the_scene_built_directly_agree() {
        let text = spheres_toml(200, 3);
        let parsed = crate::io::scene_file::parse(&text, "generated").unwrap();
        assert_eq!(parsed, scene(200, 3));
    }

    #[test]
    fn spheres_rest_on_the_floor_inside_the_patch() {
        for b in spheres(1000, 1) {
            assert!((b.center[1] - b.radius - FLOOR).abs() < 1e-5, "{b:?}");
            assert!(b.center[0].abs() <= 5.0 && (-13.0..=-1.0).contains(&b.center[2]));
            assert!(b.radius > 0.0 && b.radius <= 0.5);
        }
    }
}
