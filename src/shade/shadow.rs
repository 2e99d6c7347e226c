//! Shadows: is there anything between the hit point and the light?

use crate::ray::Ray;
use crate::scene::{blocked, Object};
use crate::Vec3;

/// How far the tutorial moves a hit point along the normal before casting a new
/// ray from it.
pub const NORMAL_STEP: f64 = 1e-5;

// ANCHOR: step_off
/// The hit point moved a little along the surface normal. A ray cast from the
/// exact hit point could find the same surface again at a tiny distance, because
/// the computed point lies a rounding error inside or outside it ("shadow acne").
pub fn step_off(point: Vec3, normal: Vec3) -> Vec3 {
    point + normal * NORMAL_STEP
}
// ANCHOR_END: step_off

// ANCHOR: in_shadow
/// The tutorial's shadow test: cast a ray from the moved point `shifted` towards the
/// light (`to_light`, a unit vector). The point is in shadow if an object is hit
/// closer than the light, whose distance `light_distance` is measured from the
/// original hit point.
pub fn in_shadow(objects: &[Object], shifted: Vec3, to_light: Vec3, light_distance: f64) -> bool {
    let shadow_ray = Ray {
        origin: shifted,
        direction: to_light,
    };
    blocked(objects, &shadow_ray, light_distance)
}
// ANCHOR_END: in_shadow
