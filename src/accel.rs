//! Skipping the tests that cannot succeed: how raystep finds the nearest hit fast
//! without changing which hit it finds.
//!
//! The book's [`nearest_hit`](crate::scene::nearest_hit) tests every object. Two
//! things make that cheaper, and neither changes a pixel:
//!
//! - **A bounding volume hierarchy** ([`Bvh`](crate::bvh::Bvh)) over the spheres,
//!   for scenes with many of them: a ray visits only the boxes it crosses. The
//!   book's tracer asks it through [`Tracer::nearest_hit`](crate::render::Tracer::nearest_hit)
//!   and `in_shadow`, which name no structure in the listings.
//! - **Tiles of primary rays**, in the fast engine (`src/fast/masks.rs`). Every
//!   primary ray starts at the camera, so the rays of a tile of 16 × 8 pixels lie
//!   inside a pyramid with its apex at the camera; an object entirely outside it
//!   cannot be hit by any of them, and each tile keeps a bit mask of the objects
//!   that can.
//!
//! `--accel off` turns both off (the plain loop, exactly the book's code);
//! `--accel auto` (the default) uses the masks (in the fast engine), and the BVH
//! instead only when the scene has at least [`BVH_FROM`] spheres, below which
//! plain iteration measured faster with the fast engine (the book engine shares
//! the threshold); `--accel bvh` forces the BVH. The textbook quadratic gets no BVH: its
//! false hits far outside a sphere (chapter 9) would fall outside the boxes.

use crate::sphere::Method;

/// How the nearest hit is searched for (`--accel`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Accel {
    /// Test every object for every ray: the book's plain loop.
    Off,
    /// A BVH from 24 spheres on (the constant BVH_FROM); in the fast engine also
    /// tile masks for primary rays.
    #[default]
    Auto,
    /// A BVH whatever the number of spheres (but never with --intersect naive).
    Bvh,
}

impl Accel {
    /// Whether a tracer under this choice builds a BVH over `spheres` spheres
    /// met by `method`. The one place that decides it: the book's tracer (and so
    /// the fast engine, built on it), `bench` (which times the build), `chart
    /// --scale` and `--accel bvh`'s warning all ask here. The
    /// textbook quadratic gets none: its false hits far outside a sphere (chapter
    /// 9) would fall outside the boxes and change the picture.
    pub fn builds_bvh(self, spheres: usize, method: Method) -> bool {
        match self {
            _ if method == Method::Naive => false,
            Accel::Off => false,
            Accel::Auto => spheres >= BVH_FROM,
            Accel::Bvh => true,
        }
    }
}

impl std::fmt::Display for Accel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Accel::Off => "off",
            Accel::Auto => "auto",
            Accel::Bvh => "bvh",
        })
    }
}

/// From this many spheres on, `--accel auto` builds a BVH. Measured at
/// 1920 × 1080 with `raystep bench SCENE --no-yardstick --accel auto|bvh` on
/// `raystep generate spheres --count N` scenes (N spheres and the floor), both
/// four rays at a time ([`crate::fast::packet`]): the plain loop with tile masks took
/// 0.135 s at 12 spheres against the BVH's 0.171 s, 0.219 s at 24 against
/// 0.208 s, and 0.314 s at 48 against 0.266 s. (One ray at a time, the BVH paid
/// from 12 spheres.) With the packets' float32 box test the plain loop still won
/// at 12 spheres (0.124–0.134 s against 0.143–0.151 s), and at 16 the two were
/// within noise (0.138–0.149 s against 0.125–0.170 s).
pub const BVH_FROM: usize = 24;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bvh_is_built_from_bvh_from_spheres_on_or_when_asked_but_never_for_the_quadratic() {
        let stable = Method::Stable;
        assert!(!Accel::Auto.builds_bvh(BVH_FROM - 1, stable));
        assert!(Accel::Auto.builds_bvh(BVH_FROM, stable));
        assert!(!Accel::Off.builds_bvh(100_000, stable));
        assert!(Accel::Bvh.builds_bvh(0, stable));
        for accel in [Accel::Off, Accel::Auto, Accel::Bvh] {
            assert!(!accel.builds_bvh(100_000, Method::Naive), "{accel}");
        }
    }
}
