//! The scene: objects with their materials, the light, the camera, and the two
//! questions every ray asks of them: "what do I hit first?" and "is anything in
//! between?".

use crate::camera::{Camera, Screen};
use crate::plane::Plane;
use crate::ray::Ray;
use crate::real::{Real, Vec3Num, Vector};
use crate::sphere::{outward_normal, Method, Sphere};
use crate::stages::Stages;
use crate::Vec3;

/// Largest magnitude accepted for any number in a scene: squares of coordinates
/// stay far inside float32's and float64's range.
pub const MAX_MAGNITUDE: f64 = 1e15;

/// How a surface answers light (the Blinn-Phong coefficients and the mirror weight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material<T: Real = f64> {
    /// Colour under ambient light, `ka`.
    pub ambient: T::Vec3,
    /// Colour under direct light, `kd`; also the flat colour of the `intersection` stage.
    pub diffuse: T::Vec3,
    /// Colour of the highlight, `ks`.
    pub specular: T::Vec3,
    /// How tight the highlight is; the exponent of `N·H` is `shininess / 4`.
    pub shininess: T,
    /// Fraction of the reflected colour that is added, from 0 (matte) to 1 (mirror).
    pub reflection: T,
}

/// The geometry of an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape<T: Real = f64> {
    /// A sphere (the tutorial's only shape; its fake plane is one too).
    Sphere(Sphere<T>),
    /// A true, infinite plane.
    Plane(Plane<T>),
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
pub struct Object<T: Real = f64> {
    /// Its geometry.
    pub shape: Shape<T>,
    /// Its surface.
    pub material: Material<T>,
    /// Which scene-file section it came from.
    pub role: Role,
}

/// The point light: a position that shines equally in all directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light<T: Real = f64> {
    /// Where the light is.
    pub position: T::Vec3,
    /// Its ambient colour, `la`.
    pub ambient: T::Vec3,
    /// Its diffuse colour, `ld`.
    pub diffuse: T::Vec3,
    /// Its specular colour, `ls`.
    pub specular: T::Vec3,
}

impl Light {
    /// The same light in precision `T`.
    pub fn cast<T: Real>(&self) -> Light<T> {
        Light {
            position: T::Vec3::of(self.position),
            ambient: T::Vec3::of(self.ambient),
            diffuse: T::Vec3::of(self.diffuse),
            specular: T::Vec3::of(self.specular),
        }
    }
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
    /// The `[[sphere]]` entries in file order, then the spheres of `[generate]`,
    /// then the `[[plane]]` entries in file order.
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
    /// The objects that take part under `stages`, in precision `T`: `[[plane]]`
    /// entries only from the `plane` stage on.
    pub fn objects_in_play<T: Real>(&self, stages: Stages) -> Vec<Object<T>> {
        self.objects
            .iter()
            .filter(|o| o.role == Role::Sphere || stages.plane)
            .map(Object::cast)
            .collect()
    }
    // ANCHOR_END: objects_in_play
}

/// The nearest object a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit<T: Real = f64> {
    /// Distance along the ray.
    pub t: T,
    /// Index of the object in the slice that was searched.
    pub object: usize,
}

// ANCHOR: object_intersect
impl<T: Real> Object<T> {
    /// Distance along `ray` to this object, if it is hit (spheres by `method`).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray<T>, method: Method) -> Option<T> {
        match &self.shape {
            Shape::Sphere(s) => s.intersect(ray, method),
            Shape::Plane(p) => p.intersect(ray),
        }
    }

    /// The unit normal at the point `p` where `ray` hit this object.
    #[inline]
    pub fn normal_at(&self, p: T::Vec3, ray: &Ray<T>) -> T::Vec3 {
        match &self.shape {
            Shape::Sphere(s) => s.normal_at(p),
            Shape::Plane(pl) => pl.normal_towards(ray),
        }
    }
}

// ANCHOR_END: object_intersect

// ANCHOR: nearest_hit
/// The first object along `ray`: test them all, keep the smallest distance.
#[inline(always)]
pub fn nearest_hit<T: Real>(objects: &[Object<T>], ray: &Ray<T>, method: Method) -> Option<Hit<T>> {
    let mut nearest: Option<Hit<T>> = None;
    for (index, object) in objects.iter().enumerate() {
        if let Some(t) = object.intersect(ray, method) {
            if nearest.is_none_or(|n| t < n.t) {
                nearest = Some(Hit { t, object: index });
            }
        }
    }
    nearest
}

/// Is any object hit along `ray` closer than `distance`? The shadow test needs
/// only a yes or a no, so it stops at the first blocker it finds.
#[inline(always)]
pub fn blocked<T: Real>(objects: &[Object<T>], ray: &Ray<T>, distance: T, method: Method) -> bool {
    for object in objects {
        if object.intersect(ray, method).is_some_and(|t| t < distance) {
            return true;
        }
    }
    false
}
// ANCHOR_END: nearest_hit

/// One step of a search for the nearest hit that visits the objects in another
/// order than [`nearest_hit`] (the BVH's one-ray walk; the packets keep their hits
/// by the same rule): test object `index` and keep it in `nearest` if it is
/// nearer, or as near with a lower index, so that the result is the plain loop's
/// whatever the order.
#[inline]
pub fn consider<T: Real>(
    objects: &[Object<T>],
    ray: &Ray<T>,
    method: Method,
    index: usize,
    nearest: &mut Option<Hit<T>>,
) {
    if let Some(t) = objects[index].intersect(ray, method) {
        if nearest.is_none_or(|n| t < n.t || (t == n.t && index < n.object)) {
            *nearest = Some(Hit { t, object: index });
        }
    }
}

impl<T: Real> Object<T> {
    /// The point of the surface nearest to `p`, a point computed to be on it:
    /// moved along the sphere's radius, or along the plane's normal.
    #[inline]
    pub fn project(&self, p: T::Vec3) -> T::Vec3 {
        match &self.shape {
            Shape::Sphere(s) => on_sphere(s.center, outward_normal(p, s.center), s.radius),
            Shape::Plane(pl) => on_plane(p, pl.point, pl.normal),
        }
    }

    /// [`Object::project`] of a point `p` whose unit normal `normal` is already
    /// known: for a sphere `C + N·r` (the normal is the direction from the centre
    /// to `p`, so this is the same number without a second square root), for a
    /// plane the same as `project`.
    #[inline]
    pub fn surface_point(&self, p: T::Vec3, normal: T::Vec3) -> T::Vec3 {
        match &self.shape {
            Shape::Sphere(s) => on_sphere(s.center, normal, s.radius),
            Shape::Plane(_) => self.project(p),
        }
    }

    /// The size of the numbers this surface is computed from (the largest
    /// coordinate of the centre plus the radius, or of the plane's point): rounding
    /// errors of anything computed on it grow with this (the `scene` offset).
    #[inline]
    pub fn magnitude(&self) -> T {
        match &self.shape {
            Shape::Sphere(s) => s.center.max_abs() + s.radius,
            Shape::Plane(pl) => pl.point.max_abs(),
        }
    }
}

/// The point of the sphere of `center` and `radius` in the direction of the unit
/// `normal`: `C + N·r`. (For any [`Vec3Num`], as the fast engine computes it.)
#[inline(always)]
pub fn on_sphere<V: Vec3Num>(center: V, normal: V, radius: V::Num) -> V {
    center + normal * radius
}

/// The point of the plane through `point` with unit `normal` nearest to `p`:
/// `p − n·⟨p − P, n⟩`. (For any [`Vec3Num`], as the fast engine computes it.)
#[inline(always)]
pub fn on_plane<V: Vec3Num>(p: V, point: V, normal: V) -> V {
    p - normal * (p - point).dot(normal)
}

impl<T: Real> Object<T> {
    /// The same object in float64, exactly: every number of precision `T` is a
    /// float64 number too.
    pub fn exact(&self) -> Object {
        let shape = match self.shape {
            Shape::Sphere(s) => Shape::Sphere(Sphere {
                center: s.center.to_f64(),
                radius: s.radius.to_f64(),
            }),
            Shape::Plane(p) => Shape::Plane(Plane {
                point: p.point.to_f64(),
                normal: p.normal.to_f64(),
            }),
        };
        let m = &self.material;
        Object {
            shape,
            material: Material {
                ambient: m.ambient.to_f64(),
                diffuse: m.diffuse.to_f64(),
                specular: m.specular.to_f64(),
                shininess: m.shininess.to_f64(),
                reflection: m.reflection.to_f64(),
            },
            role: self.role,
        }
    }
}

impl Object {
    /// The same object in precision `T`.
    pub fn cast<T: Real>(&self) -> Object<T> {
        let shape = match self.shape {
            Shape::Sphere(s) => Shape::Sphere(Sphere {
                center: T::Vec3::of(s.center),
                radius: T::of(s.radius),
            }),
            Shape::Plane(p) => Shape::Plane(Plane {
                point: T::Vec3::of(p.point),
                normal: T::Vec3::of(p.normal),
            }),
        };
        let m = &self.material;
        Object {
            shape,
            material: Material {
                ambient: T::Vec3::of(m.ambient),
                diffuse: T::Vec3::of(m.diffuse),
                specular: T::Vec3::of(m.specular),
                shininess: T::of(m.shininess),
                reflection: T::of(m.reflection),
            },
            role: self.role,
        }
    }
}
