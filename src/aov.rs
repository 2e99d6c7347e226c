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
//! | `position` | `intersection` on | `P`, the first hit's point in world space: the primary ray's origin + `depth`·direction, computed again from the camera as `direction` is, in the frame's precision, with the `depth` the record keeps (float32); `(0, 0, 0)` on a miss, as `normal` and as renderers' position passes (Cycles', Arnold's) give it: compositing filters spread a NaN over its neighbours, and `Z` = `+∞` or `object` = `−1` already tell a miss from a hit at the origin |
//! | `shadow` | `intersection` on | `1` lit, `0` in shadow, `−1` on a miss. Before the `shadow` stage is on no shadow ray is cast, so every hit reads `1` |
//! | `object` | `intersection` on | index of the object hit first, among the objects in play (the file's spheres in file order, then those of its `[generate]` section, then the `[[plane]]` entries); `−1` on a miss |
//! | `ambient`, `diffuse`, `specular` | `blinn-phong` on | the three Blinn-Phong terms of the first hit (`ka·la`, `kd·ld·(L·N)`, `ks·ls·(N·H)^(shininess/4)`), as added to the pixel; `0` in shadow and on a miss, where none is computed |
//! | `bounces` | `reflection` on | reflected rays the pixel's path traced: 0 to `max_depth − 1` |
//! | `rays` | `intersection` on | every ray the pixel traced (primary, shadow and reflected, of the centre ray and of every sample): where the time goes |

use rayon::prelude::*;

use crate::camera::Camera;
use crate::real::{Precision, Vector};
use crate::stages::{Engine, Stages};
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
    /// World position of the first hit (`P`).
    Position,
    /// Lit, shadowed or missed.
    Shadow,
    /// Which object the primary ray hit first.
    Object,
    /// Blinn-Phong's ambient term at the first hit.
    Ambient,
    /// Blinn-Phong's diffuse term at the first hit.
    Diffuse,
    /// Blinn-Phong's specular term at the first hit.
    Specular,
    /// Reflected rays along the pixel's path.
    Bounces,
    /// Rays the pixel traced.
    Rays,
}

impl Buffer {
    /// Every buffer, in the order files are written.
    pub const ALL: [Buffer; 12] = [
        Buffer::Beauty,
        Buffer::Direction,
        Buffer::Depth,
        Buffer::Normal,
        Buffer::Position,
        Buffer::Shadow,
        Buffer::Object,
        Buffer::Ambient,
        Buffer::Diffuse,
        Buffer::Specular,
        Buffer::Bounces,
        Buffer::Rays,
    ];

    /// The name of the buffer and of its PNG file (without `.png`).
    pub fn name(self) -> &'static str {
        match self {
            Buffer::Beauty => "beauty",
            Buffer::Direction => "direction",
            Buffer::Depth => "depth",
            Buffer::Normal => "normal",
            Buffer::Position => "position",
            Buffer::Shadow => "shadow",
            Buffer::Object => "object",
            Buffer::Ambient => "ambient",
            Buffer::Diffuse => "diffuse",
            Buffer::Specular => "specular",
            Buffer::Bounces => "bounces",
            Buffer::Rays => "rays",
        }
    }

    /// Does a render of `stages` write this buffer? Only what a stage computes is
    /// written: no Blinn-Phong terms before that stage, no bounces before
    /// reflection.
    pub fn written(self, stages: Stages) -> bool {
        match self {
            Buffer::Beauty | Buffer::Direction => true,
            Buffer::Depth
            | Buffer::Normal
            | Buffer::Position
            | Buffer::Shadow
            | Buffer::Object
            | Buffer::Rays => stages.intersection,
            Buffer::Ambient | Buffer::Diffuse | Buffer::Specular => {
                stages.intersection && stages.blinn_phong
            }
            Buffer::Bounces => stages.intersection && stages.reflection,
        }
    }
}

/// Rays traced, by kind: what the `rays` buffer and `raystep bench` count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rays {
    /// Rays from the camera: one a pixel, the centre ray the buffers describe,
    /// and with `--spp N` (N > 1) N more, the samples.
    pub primary: u64,
    /// Rays from a hit point towards the light.
    pub shadow: u64,
    /// Rays from a hit point in the mirrored direction.
    pub reflection: u64,
    /// Paths the book's [`Tracer::trace`](crate::render::Tracer::trace) followed,
    /// counted inside it at their first segment: not rays, and in no total.
    /// Every pixel's (and sample's) with the book engine past the `rays` stage,
    /// none where the fast engine traced them in packets. A test holds the
    /// default render to it, so that the book's code is the code that renders.
    pub paths: u64,
}

impl Rays {
    /// Every ray, whatever its kind.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflection
    }
}

impl std::ops::AddAssign for Rays {
    fn add_assign(&mut self, other: Rays) {
        self.primary += other.primary;
        self.shadow += other.shadow;
        self.reflection += other.reflection;
        self.paths += other.paths;
    }
}

/// How a frame's pixels were traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Packets {
    /// One ray at a time: the book's engine (chosen, or the fast engine's
    /// fallback for a scene it does not take in packets).
    Off,
    /// Four at a time, the build for any processor (two float64 lanes to a
    /// register on x86-64: SSE2).
    Baseline,
    /// Four at a time, the AVX build (four float64 lanes to a register).
    Avx,
}

impl Packets {
    /// `"off"`, `"baseline"` or `"avx"`.
    pub fn name(self) -> &'static str {
        match self {
            Packets::Off => "off",
            Packets::Baseline => "baseline",
            Packets::Avx => "avx",
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
    /// `L·N` of Blinn-Phong's diffuse term; 0 where none was computed (the
    /// stage off, or the point in shadow).
    pub diffuse: f64,
    /// `(N·H)^(shininess/4)` of its specular term; 0 where none was computed.
    pub specular: f64,
}
// ANCHOR_END: first_hit

/// The `object` of a pixel whose primary ray hit nothing.
pub const NO_OBJECT: u32 = u32::MAX;

/// The size of a [`PixelRecord`]: 13 numbers of 4 bytes (checked when compiled).
pub const RECORD_BYTES: usize = 52;
const _: () = assert!(std::mem::size_of::<PixelRecord>() == RECORD_BYTES);

/// Everything the render keeps of one pixel, in float32: enough for every buffer
/// but `direction`, which the camera gives again for any pixel
/// ([`Frame::direction`]). The Blinn-Phong terms are kept as their factors `L·N`
/// and `(N·H)^(shininess/4)`; the colours they multiply are the object's
/// ([`Frame::term_colours`]). 52 bytes ([`RECORD_BYTES`]).
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
    /// The object hit first, [`NO_OBJECT`] on a miss.
    pub object: u32,
    /// `L·N` at the first hit, 0 where Blinn-Phong was not computed.
    pub diffuse: f32,
    /// `(N·H)^(shininess/4)` at the first hit, 0 where Blinn-Phong was not computed.
    pub specular: f32,
    /// Reflected rays the path traced.
    pub bounces: u32,
    /// Every ray the pixel traced.
    pub rays: u32,
}

impl PixelRecord {
    /// The record of a pixel that ended with `colour`, whose first hit (if any)
    /// was `first`, whose path bounced `bounces` times and which traced `rays`.
    pub fn new(colour: Vec3, first: Option<FirstHit>, bounces: u64, rays: u64) -> PixelRecord {
        let mut record = PixelRecord::missed(colour.as_vec3().to_array(), bounces, rays);
        if let Some(hit) = first {
            record.set_hit(
                hit.depth as f32,
                hit.normal.as_vec3().to_array(),
                hit.lit,
                hit.object,
                hit.diffuse as f32,
                hit.specular as f32,
            );
        }
        record
    }

    /// The record of a pixel whose primary ray hit nothing: [`PixelRecord::new`]
    /// with no first hit, the colour already in float32.
    pub fn missed(colour: [f32; 3], bounces: u64, rays: u64) -> PixelRecord {
        PixelRecord {
            colour,
            depth: f32::INFINITY,
            normal: [0.0; 3],
            shadow: -1.0,
            object: NO_OBJECT,
            diffuse: 0.0,
            specular: 0.0,
            bounces: saturate(bounces),
            rays: saturate(rays),
        }
    }

    /// Record the first hit, its numbers (those of [`FirstHit`]) already in
    /// float32.
    pub fn set_hit(
        &mut self,
        depth: f32,
        normal: [f32; 3],
        lit: bool,
        object: usize,
        diffuse: f32,
        specular: f32,
    ) {
        // A hit beyond float32's range (a plane met almost edge-on) is stored as
        // the largest float32: still a hit, not the +∞ of a miss.
        self.depth = depth.min(f32::MAX);
        self.normal = normal;
        self.shadow = if lit { 1.0 } else { 0.0 };
        self.object = saturate(object as u64);
        self.diffuse = diffuse;
        self.specular = specular;
    }

    /// Did the primary ray hit anything?
    pub fn is_hit(&self) -> bool {
        self.depth.is_finite()
    }
}

/// `n` as a record's `u32`, the largest one if it is larger.
fn saturate(n: u64) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// A rendered image: a record per pixel, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The stages that made it (which decide the buffers it has).
    pub stages: Stages,
    /// For each object in play, the colours its Blinn-Phong terms multiply:
    /// `ka·la`, `kd·ld` and `ks·ls`.
    pub term_colours: Vec<[Vec3; 3]>,
    /// The camera that made the primary rays.
    pub camera: Camera,
    /// The precision they were computed in.
    pub precision: Precision,
    /// The rays traced for the whole frame.
    pub rays: Rays,
    /// The engine that traced the pixels (`raystep bench` reports it).
    pub engine: Engine,
    /// How the fast engine traced them: one ray at a time (the book's engine), or
    /// which build of its packet loop ran.
    pub packets: Packets,
    /// `width × height` records, row-major, top row first.
    pub pixels: Vec<PixelRecord>,
}

impl Frame {
    /// A frame of `camera`'s size with every record blank, to render into.
    pub fn blank(camera: Camera, precision: Precision) -> Frame {
        let blank = PixelRecord::new(Vec3::ZERO, None, 0, 0);
        Frame {
            width: camera.width,
            height: camera.height,
            stages: Stages::up_to(crate::stages::Stage::Rays),
            term_colours: Vec::new(),
            camera,
            precision,
            rays: Rays::default(),
            engine: Engine::Book,
            packets: Packets::Off,
            // Filled on every thread: the first touch of each page of a fresh
            // frame (108 MB at 1920 × 1080) is the kernel's work, and sharing
            // it took a sixth off the fast engine's `render` seconds there.
            pixels: {
                let mut pixels = Vec::new();
                let count = camera.width as usize * camera.height as usize;
                pixels.par_extend(rayon::iter::repeat_n(blank, count));
                pixels
            },
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

    /// The world position `P` of pixel (`row`, `col`)'s first hit: its primary ray
    /// computed again as [`Frame::direction`] does, walked the record's `depth`
    /// along (`origin + depth·direction`, in the frame's precision); `(0, 0, 0)`
    /// on a miss.
    pub fn position(&self, row: u32, col: u32) -> [f32; 3] {
        self.ray_buffers(row, col).1
    }

    /// [`Frame::direction`] and [`Frame::position`] of one pixel, its primary ray
    /// computed once for both.
    #[inline]
    pub fn ray_buffers(&self, row: u32, col: u32) -> ([f32; 3], [f32; 3]) {
        let record = self.at(row, col);
        match self.precision {
            Precision::F32 => self.ray_buffers_in::<f32>(row, col, record),
            Precision::F64 => self.ray_buffers_in::<f64>(row, col, record),
        }
    }

    /// [`Frame::ray_buffers`] of columns `cols` of row `row`, appended to `out`
    /// (the precision looked at once for the row, not once a pixel).
    pub fn ray_buffers_row(
        &self,
        row: u32,
        cols: std::ops::Range<u32>,
        out: &mut Vec<([f32; 3], [f32; 3])>,
    ) {
        let records = cols.map(|col| (col, self.at(row, col)));
        match self.precision {
            Precision::F32 => {
                out.extend(records.map(|(c, r)| self.ray_buffers_in::<f32>(row, c, r)))
            }
            Precision::F64 => {
                out.extend(records.map(|(c, r)| self.ray_buffers_in::<f64>(row, c, r)))
            }
        }
    }

    #[inline]
    fn ray_buffers_in<T: crate::real::Real>(
        &self,
        row: u32,
        col: u32,
        record: &PixelRecord,
    ) -> ([f32; 3], [f32; 3]) {
        let ray = self.camera.primary_ray::<T>(row, col);
        let direction = ray.direction.to_f64().as_vec3().to_array();
        let position = if record.is_hit() {
            let t = T::of(f64::from(record.depth));
            ray.at(t).to_f64().as_vec3().to_array()
        } else {
            [0.0; 3]
        };
        (direction, position)
    }

    /// The buffers this frame holds, in file order.
    pub fn buffers(&self) -> impl Iterator<Item = Buffer> + '_ {
        Buffer::ALL.into_iter().filter(|b| b.written(self.stages))
    }

    /// Does the frame hold `buffer`?
    pub fn has(&self, buffer: Buffer) -> bool {
        buffer.written(self.stages)
    }

    /// The ambient, diffuse and specular terms of `record`'s first hit, as they
    /// were added to its colour (zero where none was computed).
    pub fn terms(&self, record: &PixelRecord) -> [[f32; 3]; 3] {
        let lit = record.shadow == 1.0 && self.stages.blinn_phong;
        match self.term_colours.get(record.object as usize) {
            Some([ambient, diffuse, specular]) if lit => [
                ambient.as_vec3().to_array(),
                (*diffuse * f64::from(record.diffuse)).as_vec3().to_array(),
                (*specular * f64::from(record.specular))
                    .as_vec3()
                    .to_array(),
            ],
            _ => [[0.0; 3]; 3],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{FirstHit, PixelRecord, NO_OBJECT};
    use crate::Vec3;

    fn hit_at(depth: f64) -> FirstHit {
        FirstHit {
            depth,
            normal: Vec3::Y,
            lit: false,
            object: 2,
            diffuse: 0.0,
            specular: 0.0,
        }
    }

    /// A hit farther than float32 reaches (a plane met almost edge-on, 1e39
    /// along the ray) is kept as a hit at the largest float32, never the +∞
    /// that marks a miss; a miss stays +∞.
    #[test]
    fn a_hit_beyond_float32s_range_is_still_a_hit() {
        for depth in [1e39, 1e300, f64::from(f32::MAX) * 2.0] {
            let record = PixelRecord::new(Vec3::ZERO, Some(hit_at(depth)), 0, 2);
            assert_eq!(record.depth, f32::MAX, "{depth:e}");
            assert!(record.is_hit(), "{depth:e}");
            assert_eq!((record.shadow, record.object), (0.0, 2), "{depth:e}");
        }
        let near = PixelRecord::new(Vec3::ZERO, Some(hit_at(1.5)), 0, 2);
        assert_eq!(near.depth, 1.5);
        let missed = PixelRecord::new(Vec3::ZERO, None, 0, 1);
        assert_eq!((missed.depth, missed.object), (f32::INFINITY, NO_OBJECT));
        assert!(!missed.is_hit());
    }
}
