//! The debug buffers (AOVs, "arbitrary output variables") and the first-hit record
//! that fills them.
//!
//! Shading and buffers read the same record: the buffers are a by-product of the
//! render, not a second renderer. The exact definitions:
//!
//! | buffer | written by | value |
//! |---|---|---|
//! | `beauty` | every stage | the pixel's colour, clipped to [0, 1] (linear, no gamma) |
//! | `direction` | `rays` (always on) | the primary ray's unit direction, world space |
//! | `depth` | `intersection` on | distance along the primary ray to the first hit (the ray's `t`; the direction is a unit vector, so this is the distance from the camera); `+∞` on a miss |
//! | `normal` | `intersection` on | unit world-space normal at the first hit (outward for a sphere, towards the camera for a plane); `(0, 0, 0)` on a miss |
//! | `shadow` | `intersection` on | `1` lit, `0` in shadow, `−1` on a miss. Before the `shadow` stage is on no shadow ray is cast, so every hit reads `1` |

use crate::camera::Camera;
use crate::real::{Precision, Vector};
use crate::render::Rays;
use crate::Vec3;

/// One buffer, named as its PNG file is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Buffer {
    /// The picture itself.
    Beauty,
    /// The primary ray's direction.
    Direction,
    /// Distance to the first hit.
    Depth,
    /// Normal at the first hit.
    Normal,
    /// Lit, shadowed or missed.
    Shadow,
}

impl Buffer {
    /// Every buffer, in the order files are written.
    pub const ALL: [Buffer; 5] = [
        Buffer::Beauty,
        Buffer::Direction,
        Buffer::Depth,
        Buffer::Normal,
        Buffer::Shadow,
    ];

    /// The name of the buffer and of its PNG file (without `.png`).
    pub fn name(self) -> &'static str {
        match self {
            Buffer::Beauty => "beauty",
            Buffer::Direction => "direction",
            Buffer::Depth => "depth",
            Buffer::Normal => "normal",
            Buffer::Shadow => "shadow",
        }
    }

    /// Does a render with the `intersection` stage on (or off) write this buffer?
    pub fn written(self, intersection: bool) -> bool {
        match self {
            Buffer::Beauty | Buffer::Direction => true,
            Buffer::Depth | Buffer::Normal | Buffer::Shadow => intersection,
        }
    }
}

// ANCHOR: first_hit
/// What the first hit of a pixel's primary ray leaves behind for the buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstHit {
    /// Distance along the primary ray.
    pub depth: f64,
    /// Unit normal at the hit point.
    pub normal: Vec3,
    /// Does the point see the light? (Always `true` before the `shadow` stage.)
    pub lit: bool,
    /// Index of the object hit, among the objects in play.
    pub object: usize,
}
// ANCHOR_END: first_hit

/// Everything the render keeps of one pixel, in float32: enough for every buffer
/// but `direction`, which the camera gives again for any pixel
/// ([`Frame::direction`]). 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRecord {
    /// The beauty colour, clipped to [0, 1].
    pub colour: [f32; 3],
    /// Distance to the first hit, `+∞` on a miss.
    pub depth: f32,
    /// Unit normal at the first hit, zero on a miss.
    pub normal: [f32; 3],
    /// 1 lit, 0 in shadow, −1 on a miss.
    pub shadow: f32,
}

impl PixelRecord {
    /// The record of a pixel that ended with `colour` and whose first hit (if any)
    /// was `first`.
    pub fn new(colour: Vec3, first: Option<FirstHit>) -> PixelRecord {
        let (depth, normal, shadow) = match first {
            Some(hit) => (hit.depth, hit.normal, if hit.lit { 1.0 } else { 0.0 }),
            None => (f64::INFINITY, Vec3::ZERO, -1.0),
        };
        PixelRecord {
            colour: colour.as_vec3().to_array(),
            depth: depth as f32,
            normal: normal.as_vec3().to_array(),
            shadow,
        }
    }

    /// Did the primary ray hit anything?
    pub fn is_hit(&self) -> bool {
        self.depth.is_finite()
    }
}

/// A rendered image: a record per pixel, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Was the `intersection` stage on (so that depth, normal and shadow mean something)?
    pub has_surface_buffers: bool,
    /// The camera that made the primary rays.
    pub camera: Camera,
    /// The precision they were computed in.
    pub precision: Precision,
    /// The rays traced for the whole frame.
    pub rays: Rays,
    /// `width × height` records, row-major, top row first.
    pub pixels: Vec<PixelRecord>,
}

impl Frame {
    /// A frame of `camera`'s size with every record blank, to render into.
    pub fn blank(camera: Camera, precision: Precision) -> Frame {
        let blank = PixelRecord::new(Vec3::ZERO, None);
        Frame {
            width: camera.width,
            height: camera.height,
            has_surface_buffers: false,
            camera,
            precision,
            rays: Rays::default(),
            pixels: vec![blank; camera.width as usize * camera.height as usize],
        }
    }

    /// The record of pixel (`row`, `col`).
    pub fn at(&self, row: u32, col: u32) -> &PixelRecord {
        &self.pixels[row as usize * self.width as usize + col as usize]
    }

    /// The unit direction of pixel (`row`, `col`)'s primary ray, computed again as
    /// the render computed it (the pixel's centre ray, in the frame's precision).
    pub fn direction(&self, row: u32, col: u32) -> [f32; 3] {
        let d = match self.precision {
            Precision::F32 => self.camera.primary_ray::<f32>(row, col).direction.to_f64(),
            Precision::F64 => self.camera.primary_ray::<f64>(row, col).direction,
        };
        d.as_vec3().to_array()
    }

    /// The buffers this frame holds, in file order.
    pub fn buffers(&self) -> impl Iterator<Item = Buffer> + '_ {
        Buffer::ALL
            .into_iter()
            .filter(|b| b.written(self.has_surface_buffers))
    }
}
