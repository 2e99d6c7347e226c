//! The scene: objects with their materials, the light, the camera, and the two
//! questions every ray asks of them: "what do I hit first?" and "is anything in
//! between?".

use crate::camera::{Camera, Screen};
use crate::plane::Plane;
use crate::ray::Ray;
use crate::sphere::Sphere;
use crate::stages::Stages;
use crate::Vec3;

/// How a surface answers light (the Blinn-Phong coefficients and the mirror weight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Colour under ambient light, `ka`.
    pub ambient: Vec3,
    /// Colour under direct light, `kd`; also the flat colour of the `intersection` stage.
    pub diffuse: Vec3,
    /// Colour of the highlight, `ks`.
    pub specular: Vec3,
    /// How tight the highlight is; the exponent of `N·H` is `shininess / 4`.
    pub shininess: f64,
    /// Fraction of the reflected colour that is added, from 0 (matte) to 1 (mirror).
    pub reflection: f64,
}

/// The geometry of an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere (the tutorial's only shape; its fake plane is one too).
    Sphere(Sphere),
    /// A true, infinite plane.
    Plane(Plane),
}

/// Where an object came from in the scene file. Objects of `[[plane]]` entries are
/// drawn only once the `plane` stage is on, whatever their shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A `[[sphere]]` entry.
    Sphere,
    /// A `[[plane]]` entry: the floor, fake or true.
    Floor,
}

/// One thing in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    /// Its geometry.
    pub shape: Shape,
    /// Its surface.
    pub material: Material,
    /// Which scene-file section it came from.
    pub role: Role,
}

/// The point light: a position that shines equally in all directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Where the light is.
    pub position: Vec3,
    /// Its ambient colour, `la`.
    pub ambient: Vec3,
    /// Its diffuse colour, `ld`.
    pub diffuse: Vec3,
    /// Its specular colour, `ls`.
    pub specular: Vec3,
}

/// Everything a scene file describes.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The eye.
    pub camera: Vec3,
    /// The screen if the scene sets one; otherwise [`Screen::for_image`] of the size.
    pub screen: Option<Screen>,
    /// The one point light.
    pub light: Light,
    /// Most segments of a pixel's path (the primary ray and its reflections).
    pub max_depth: u32,
    /// Spheres first, in file order, then the `[[plane]]` entries, in file order.
    pub objects: Vec<Object>,
}

impl Scene {
    /// The camera that renders this scene at its image size.
    pub fn camera(&self) -> Camera {
        Camera {
            position: self.camera,
            screen: self
                .screen
                .unwrap_or_else(|| Screen::for_image(self.width, self.height)),
            width: self.width,
            height: self.height,
        }
    }

    // ANCHOR: objects_in_play
    /// The objects that take part under `stages`: `[[plane]]` entries only from the
    /// `plane` stage on.
    pub fn objects_in_play(&self, stages: Stages) -> Vec<Object> {
        self.objects
            .iter()
            .filter(|o| o.role == Role::Sphere || stages.plane)
            .copied()
            .collect()
    }
    // ANCHOR_END: objects_in_play
}

/// The nearest object a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// Index of the object in the slice that was searched.
    pub object: usize,
}

// ANCHOR: nearest_hit
impl Object {
    /// Distance along `ray` to this object, if it is hit.
    pub fn intersect(&self, ray: &Ray) -> Option<f64> {
        match &self.shape {
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Plane(p) => p.intersect(ray),
        }
    }

    /// The unit normal at the point `p` where `ray` hit this object.
    pub fn normal_at(&self, p: Vec3, ray: &Ray) -> Vec3 {
        match &self.shape {
            Shape::Sphere(s) => s.normal_at(p),
            Shape::Plane(pl) => pl.normal_towards(ray),
        }
    }
}

/// The first object along `ray`: test them all, keep the smallest distance.
pub fn nearest_hit(objects: &[Object], ray: &Ray) -> Option<Hit> {
    let mut nearest: Option<Hit> = None;
    for (index, object) in objects.iter().enumerate() {
        if let Some(t) = object.intersect(ray) {
            if nearest.is_none_or(|n| t < n.t) {
                nearest = Some(Hit { t, object: index });
            }
        }
    }
    nearest
}

/// Is any object hit along `ray` closer than `distance`? The shadow test needs
/// only a yes or a no, so it stops at the first blocker it finds.
pub fn blocked(objects: &[Object], ray: &Ray, distance: f64) -> bool {
    objects
        .iter()
        .any(|o| o.intersect(ray).is_some_and(|t| t < distance))
}
// ANCHOR_END: nearest_hit
