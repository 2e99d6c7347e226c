//! The spheres of a generated scene: what `raystep generate spheres` lists and
//! what a scene file's `[generate]` recipe makes (`src/tools/generate.rs` writes
//! the files; `scene_file::generated_objects` makes them the scene's objects).
//!
//! N spheres rest on the tutorial's floor, spread evenly at random over a patch of
//! 10 × 12 units in front of the camera; their radius shrinks as 1/√N so that the
//! patch looks about as full at every N. Colours and mirror weights are random.
//! The numbers come from SplitMix64 and are rounded to 5 decimals before use, so
//! a scene file's text holds them exactly and the same count and seed give the
//! same spheres, listed or made from the recipe.

use crate::samples::{splitmix64, unit_interval};

/// The most spheres a recipe (`[generate] spheres = N`) may make.
pub const MAX_GENERATED: usize = 1_000_000;

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_spheres_and_another_seed_others() {
        assert_eq!(spheres(100, 7), spheres(100, 7));
        assert_ne!(spheres(100, 7), spheres(100, 8));
    }

    #[test]
    fn spheres_rest_on_the_floor_inside_the_patch() {
        for b in spheres(1000, 1) {
            assert!((b.center[1] - b.radius - FLOOR).abs() < 1e-5, "{b:?}");
            assert!(b.center[0].abs() <= 5.0 && (-13.0..=-1.0).contains(&b.center[2]));
            assert!(b.radius > 0.0 && b.radius <= 0.5);
        }
    }

    /// The radius shrinks as 1/√N: over the patch of 10 × 12 units, N spheres are
    /// √(120 / N) apart and the largest radius is 0.3 of that, each radius from
    /// 0.6 to 1 times the largest (between the clamps, 0.002 and 0.5: from about
    /// 44 to 2,700,000 spheres). At 100 spheres 0.19718 to 0.32863, at 10,000 a
    /// tenth of that.
    #[test]
    fn the_radius_shrinks_as_one_over_the_square_root_of_the_count() {
        for (count, largest) in [(100, 0.328_633), (10_000, 0.032_863_3)] {
            let balls = spheres(count, 2);
            for b in &balls {
                assert!(
                    (0.6 * largest - 1e-5..=largest + 1e-5).contains(&b.radius),
                    "{count}: {b:?}"
                );
            }
            // Their mean is 0.8 times the largest.
            let mean = balls.iter().map(|b| b.radius).sum::<f64>() / count as f64;
            assert!(
                (mean / (0.8 * largest) - 1.0).abs() < 0.05,
                "{count}: {mean}"
            );
        }
    }

    /// A ball's ambient colour is a tenth of its diffuse one (to the 7 decimals
    /// it is rounded to).
    #[test]
    fn the_ambient_colour_is_a_tenth_of_the_diffuse_one() {
        for b in spheres(500, 5) {
            for (a, d) in b.ambient.iter().zip(b.diffuse) {
                assert!((a - d / 10.0).abs() < 1e-7, "{b:?}");
            }
        }
    }
}
