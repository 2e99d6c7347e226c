//! Four rays at once: the book's [`Tracer::trace`](crate::render::Tracer::trace) for four neighbouring pixels, side by
//! side in the lanes of SIMD registers.
//!
//! The book's tracer follows one ray at a time. Each step of it waits for the one
//! before: the direction needs a square root and a division, the hit point needs
//! the distance, which needs another square root, the normal needs the point, and
//! so on, so the processor spends most of a pixel waiting for results it cannot
//! yet use. Four neighbouring pixels ask the same questions of the same objects,
//! so this module asks them together: one instruction works on four rays, and the
//! four chains of waiting overlap.
//!
//! Nothing else changes. The same formulas are computed in the same order, lane
//! by lane (see [`crate::fast::lanes`]), so every lane gives bit for bit the record the
//! scalar tracer gives for its pixel: `tests/speed.rs` compares the two on every
//! scene of the repository, and `tests/fuzz.rs` on random ones.
//!
//! Where the four rays part ways (one misses, one is in shadow, one hits another
//! sphere), each lane has a bit in a mask: lanes whose path has ended are carried
//! along but change nothing, and the packet stops when no lane is left. Each
//! object's numbers are kept in every lane ([`Packed`]), so when all four rays hit
//! the same object, as they mostly do, they are read as they are; otherwise they
//! are put together lane by lane.
//!
//! Two tests that change no result skip most of the work of a miss: a ray heading
//! away from a sphere's centre cannot meet it in front of its origin, and a ray
//! whose discriminant is not positive passes beside; when all four rays of a
//! packet are in one of those cases, the square root and the division are not
//! computed.
//!
//! The packet loop is compiled twice, once for any x86-64 processor and once for
//! one with AVX, whose registers hold four float64 lanes instead of two; which one
//! runs is chosen when the program runs ([`Fast::packet_row`], `--avx on|off`).
//! That is why the functions here are `#[inline(always)]`: only what is inlined
//! into the AVX build's entry is compiled for AVX. The two give the same bits.
//!
//! Even four at a time, a packet spends most of its time waiting on a square root
//! or a division whose result the next step needs. So two things are computed
//! earlier than the book's order would put them, to overlap with other waiting:
//! [`Fast::packet_row`] makes the primary rays of [`BATCH`] packets before it
//! traces any of them, and `trace_packet` starts the light's distance and the
//! direction to the viewer as soon as the hit point is known.
//!
//! The fast engine (`--engine fast`) traces a scene with a BVH (from
//! [`BVH_FROM`](crate::accel::BVH_FROM) spheres on with `--accel auto`, always
//! with `--accel bvh`) through it, which a packet walks together
//! (`Bvh::search_packet`, in `src/fast/walk.rs`), and one without, of up to
//! [`MAX_OBJECTS`] objects, by the plain loop (with the tile masks under
//! `--accel auto`). A larger
//! scene without a BVH (`--accel off`, or `--intersect naive`), or a render with
//! a stage `knows` does not list, is left to the book's row loop, one ray at a
//! time.

use std::borrow::Cow;

use crate::accel::Accel;
use crate::aov::{PixelRecord, Rays, RECORD_BYTES};
use crate::camera::lerp_on_grid;
use crate::fast::lanes::{components, convert, each, powi, F64s, Laned, Lanes, ALL, V3, WIDTH};
use crate::fast::masks::{TileMasks, EVERY, TILE};
use crate::fast::walk::PacketSearch;
use crate::real::{Num, Vector};
use crate::render::{direction_colour, Settings, Tracer, HALF_STEP};
use crate::samples::stratified;
use crate::scene::{on_plane, on_sphere};
use crate::scene::{Light, Object, Scene, Shape};
use crate::shade::blinn_phong::{factors, whole_exponent, Viewer};
use crate::shade::reflection::reflect;
use crate::shade::shadow::{plane_height, sphere_step, step_out, step_out_by_scene, Offset};
use crate::sphere::outward_normal;
use crate::sphere::Method;
use crate::stages::Stage;
use crate::Vec3;

// A packet's pixels must share a tile, so that they share its mask.
const _: () = assert!((TILE.0 as usize).is_multiple_of(WIDTH));

/// The most objects the packet tracer takes (one bit each in a search mask).
pub const MAX_OBJECTS: usize = 64;

/// How many packets' primary rays [`Fast::packet_row`] makes before it traces
/// them.
pub const BATCH: usize = 16;

/// What the fast engine needs beside the book's tracer.
pub struct Fast<T: Laned = f64> {
    /// The book's tracer, whose rules and objects every lane follows.
    pub book: Tracer<T>,
    /// Samples per pixel (a square number).
    pub spp: u32,
    /// For each tile of the image, the objects its primary rays can hit.
    pub masks: TileMasks,
    /// Trace four pixels at once (without a BVH only for up to [`MAX_OBJECTS`]
    /// objects).
    pub packets: bool,
    /// The objects as the packet tracer reads them; empty without packets or with
    /// a BVH.
    pub packed: Vec<Packed<T>>,
    /// Run the packet tracer's AVX build: packets are on, [`Settings::avx`] asks
    /// for it, and the processor has AVX.
    pub avx: bool,
    /// The screen's `x` at each column, for the packet tracer's primary rays
    /// (empty without packets).
    pub columns: Vec<T>,
}

impl<T: Laned> Fast<T> {
    /// The fast engine for `scene` under `settings`, computing in `T`.
    pub fn new(scene: &Scene, settings: &Settings) -> Fast<T> {
        let book = Tracer::<T>::new(scene, settings);
        assert!(
            crate::samples::check_spp(settings.spp).is_ok(),
            "spp {} is not a square from 1 to {}",
            settings.spp,
            crate::samples::MAX_SPP
        );
        // Packets search through the BVH if there is one, else a short list by bit
        // masks; a stage the packet loop does not compute is left to the book's engine.
        let known = Stage::ALL
            .iter()
            .all(|&s| !settings.stages.is_on(s) || knows(s));
        let packets = known && (book.bvh.is_some() || book.objects.len() <= MAX_OBJECTS);
        let masks = match settings.accel {
            Accel::Off => TileMasks::none(),
            Accel::Auto | Accel::Bvh if packets => TileMasks::new(&book.camera, &book.objects),
            Accel::Auto | Accel::Bvh => TileMasks::none(),
        };
        let packed = if packets && book.bvh.is_none() {
            let objects = book.objects.iter();
            objects.map(|o| Packed::new(o, &book.light)).collect()
        } else {
            Vec::new()
        };
        let columns = match packets {
            true => (0..book.camera.width)
                .map(|col| {
                    crate::fast::lanes::components::<T>(book.camera.screen_point::<T>(0, col))[0]
                })
                .collect(),
            false => Vec::new(),
        };
        Fast {
            spp: settings.spp,
            masks,
            packets,
            packed,
            avx: packets && settings.avx && has_avx(),
            columns,
            book,
        }
    }
}

/// Does the packet loop compute `stage`? A stage added to the book after it is
/// not listed here, and a render with it on falls back to the book's engine (as
/// `raystep bench` then says) until the packet loop learns it.
fn knows(stage: Stage) -> bool {
    matches!(
        stage,
        Stage::Rays
            | Stage::Intersection
            | Stage::Shadow
            | Stage::BlinnPhong
            | Stage::Reflection
            | Stage::Plane
    )
}

/// Does this processor have AVX? (Asked once; false off x86-64.)
pub fn has_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// An object as the packet tracer reads it: every number it needs, in precision
/// `T` and in every lane, worked out once per render (at each hit, for the
/// objects of a BVH) as the scalar tracer works it out at each hit. Lane `i` of
/// a blend (`Packed::blend`) holds the numbers of the object hit in lane `i`.
#[derive(Clone, Copy, Debug)]
pub struct Packed<T: Laned> {
    /// The geometry.
    shape: Shape4<T>,
    /// The sphere's radius (zero for a plane).
    radius: T::Lanes,
    /// [`Object::magnitude`], for the `scene` offset.
    magnitude: T::Lanes,
    /// `ka·la`.
    ambient: V3<T>,
    /// `kd·ld`.
    diffuse_light: V3<T>,
    /// `ks·ls`.
    specular_light: V3<T>,
    /// `kd`, the flat colour before Blinn-Phong.
    diffuse: V3<T>,
    /// The exponent of `N·H`, `shininess / 4`.
    exponent: T::Lanes,
    /// The exponent as a whole number, where [`blinn_phong::power`] takes `whole_power`
    /// ([`whole_exponent`]).
    ///
    /// [`blinn_phong::power`]: crate::shade::blinn_phong::power
    whole: [u32; WIDTH],
    /// The lanes whose exponent is not whole (and take `powf`).
    fractional: u32,
    /// The mirror weight.
    reflection: T::Lanes,
}

/// An object's geometry in every lane: what the intersection test reads.
#[derive(Clone, Copy, Debug)]
pub struct Shape4<T: Laned> {
    /// The lanes whose object is a sphere (the others are true planes).
    spheres: u32,
    /// The sphere's centre, or the plane's point.
    point: V3<T>,
    /// The plane's unit normal (zero for a sphere).
    normal: V3<T>,
    /// `r·r` (zero for a plane).
    radius_squared: T::Lanes,
}

impl<T: Laned> Shape4<T> {
    /// The sphere of centre `center` and radius `radius`.
    #[inline(always)]
    fn sphere(center: T::Vec3, radius: T) -> Shape4<T> {
        Shape4 {
            spheres: ALL,
            point: V3::splat(center),
            normal: V3::splat(T::Vec3::ZERO),
            radius_squared: T::Lanes::splat(radius * radius),
        }
    }

    /// A sphere of centre `ball[0..3]` and radius `ball[3]`, given in float64
    /// (where every number of precision `T` is exact) as the BVH keeps it.
    #[inline(always)]
    pub fn ball(ball: &[f64; 4]) -> Shape4<T> {
        let center = T::Vec3::of(Vec3::new(ball[0], ball[1], ball[2]));
        Shape4::sphere(center, T::of(ball[3]))
    }

    /// The geometry of `object`.
    #[inline(always)]
    pub fn new(object: &Object<T>) -> Shape4<T> {
        let (sphere, point, normal, radius) = geometry(object);
        Shape4 {
            spheres: if sphere { ALL } else { 0 },
            point: V3::splat(point),
            normal: V3::splat(normal),
            radius_squared: T::Lanes::splat(radius * radius),
        }
    }
}

/// What [`Shape4`] keeps of `object`: is it a sphere, its centre (or the plane's
/// point), the plane's normal (zero for a sphere), the radius (zero for a plane).
#[inline(always)]
fn geometry<T: Laned>(object: &Object<T>) -> (bool, T::Vec3, T::Vec3, T) {
    match object.shape {
        Shape::Sphere(s) => (true, s.center, T::Vec3::ZERO, s.radius),
        Shape::Plane(p) => (false, p.point, p.normal, T::of(0.0)),
    }
}

impl<T: Laned> Packed<T> {
    /// The numbers of `object` lit by `light`.
    #[inline(always)]
    pub fn new(object: &Object<T>, light: &Light<T>) -> Packed<T> {
        Packed::gather([object; WIDTH], light)
    }

    /// The numbers of `objects[i]` lit by `light` in lane `i`: what
    /// [`Packed::blend`] makes of the four objects' [`Packed::new`], without
    /// making four whole ones first (for the many objects of a BVH, which are
    /// not kept in lanes). Always inlined, as everything the packet loop calls:
    /// as a call of its own it was compiled without AVX, and took about 7 % of
    /// the fast engine's samples on 100,000 spheres (`perf record`).
    #[inline(always)]
    fn gather(objects: [&Object<T>; WIDTH], light: &Light<T>) -> Packed<T> {
        let n = T::Lanes::from_array;
        let v = V3::<T>::from_vectors;
        let shape = objects.map(geometry);
        let material = objects.map(|o| &o.material);
        let exponent = material.map(|m| m.shininess / T::of(4.0));
        let whole = exponent.map(whole_exponent);
        let lanes = |bits: [bool; WIDTH]| (0..WIDTH).fold(0, |m, i| m | u32::from(bits[i]) << i);
        Packed {
            shape: Shape4 {
                spheres: lanes(shape.map(|s| s.0)),
                point: v(shape.map(|s| s.1)),
                normal: v(shape.map(|s| s.2)),
                radius_squared: n(shape.map(|s| s.3 * s.3)),
            },
            radius: n(shape.map(|s| s.3)),
            magnitude: n(objects.map(Object::magnitude)),
            ambient: v(material.map(|m| m.ambient * light.ambient)),
            diffuse_light: v(material.map(|m| m.diffuse * light.diffuse)),
            specular_light: v(material.map(|m| m.specular * light.specular)),
            diffuse: v(material.map(|m| m.diffuse)),
            exponent: n(exponent),
            whole: whole.map(|w| w.unwrap_or(0)),
            fractional: lanes(whole.map(|w| w.is_none())),
            reflection: n(material.map(|m| m.reflection)),
        }
    }

    /// Lane `i` from `of[i]`, for every number.
    fn blend(of: [&Packed<T>; WIDTH]) -> Packed<T> {
        let n = |f: &dyn Fn(&Packed<T>) -> T::Lanes| {
            T::Lanes::from_array(std::array::from_fn(|i| f(of[i]).to_array()[i]))
        };
        let v = |f: &dyn Fn(&Packed<T>) -> V3<T>| {
            V3::new(n(&|o| f(o).x), n(&|o| f(o).y), n(&|o| f(o).z))
        };
        let bits = |f: &dyn Fn(&Packed<T>) -> u32| (0..WIDTH).fold(0, |m, i| m | f(of[i]) & 1 << i);
        Packed {
            shape: Shape4 {
                spheres: bits(&|o| o.shape.spheres),
                point: v(&|o| o.shape.point),
                normal: v(&|o| o.shape.normal),
                radius_squared: n(&|o| o.shape.radius_squared),
            },
            radius: n(&|o| o.radius),
            magnitude: n(&|o| o.magnitude),
            ambient: v(&|o| o.ambient),
            diffuse_light: v(&|o| o.diffuse_light),
            specular_light: v(&|o| o.specular_light),
            diffuse: v(&|o| o.diffuse),
            exponent: n(&|o| o.exponent),
            whole: std::array::from_fn(|i| of[i].whole[i]),
            fractional: bits(&|o| o.fractional),
            reflection: n(&|o| o.reflection),
        }
    }
}

/// Four rays: lane `i` of `origin` and `direction` is ray `i`.
#[derive(Clone, Copy, Debug)]
pub struct Packet<T: Laned> {
    /// Where the rays start.
    pub origin: V3<T>,
    /// Their unit directions.
    pub direction: V3<T>,
}

impl<T: Laned> Packet<T> {
    /// The points at distances `t`: `O + d·t`.
    #[inline(always)]
    fn at(&self, t: T::Lanes) -> V3<T> {
        self.origin + self.direction.scale(t)
    }
}

/// What [`Fast::trace_packet`] brings back, lane by lane: the colour, the first
/// hit (where `hit` has the lane's bit) and the rays traced.
struct Traced4<T: Laned> {
    /// The sum of the path's light, not yet clipped.
    colour: V3<T>,
    /// The lanes whose primary ray hit something.
    hit: u32,
    /// Of those, the lanes lit at the first hit.
    lit: u32,
    /// The lanes whose first hit got Blinn-Phong.
    shaded: u32,
    depth: T::Lanes,
    normal: V3<T>,
    object: [usize; WIDTH],
    l_dot_n: T::Lanes,
    highlight: T::Lanes,
    shadow_rays: [u32; WIDTH],
    reflection_rays: [u32; WIDTH],
}

impl<T: Laned> Traced4<T> {
    /// Black, no hit, no rays.
    #[inline(always)]
    fn blank() -> Traced4<T> {
        let zero = T::Lanes::splat(T::of(0.0));
        Traced4 {
            colour: V3::new(zero, zero, zero),
            hit: 0,
            lit: 0,
            shaded: 0,
            depth: zero,
            normal: V3::new(zero, zero, zero),
            object: [0; WIDTH],
            l_dot_n: zero,
            highlight: zero,
            shadow_rays: [0; WIDTH],
            reflection_rays: [0; WIDTH],
        }
    }

    /// Each lane's colour, clipped to [0, 1].
    #[inline(always)]
    fn colours(&self) -> [Vec3; WIDTH] {
        let c = self.colour.to_vectors();
        each(|i| c[i].clamp01().to_f64())
    }

    /// The record of each lane into `out` (as many as it holds): what
    /// [`PixelRecord::new`] makes of [`Traced4::colours`] (or the mean colour of
    /// several samples, `mean`), the lane's first hit and `rays`, converted four
    /// lanes at a time.
    #[inline(always)]
    fn write(&self, mean: Option<[Vec3; WIDTH]>, rays: &[Rays; WIDTH], out: &mut [PixelRecord]) {
        let zero = T::Lanes::splat(T::of(0.0));
        let one = T::Lanes::splat(T::of(1.0));
        // Vector::clamp01 lane by lane (a NaN stays), then float32.
        let clamp = |c: T::Lanes| c.lt(zero).select(zero, c.gt(one).select(one, c));
        let f32s = |l: T::Lanes| {
            let a = l.to_array();
            each(|i| a[i].to_f64() as f32)
        };
        let colour = match mean {
            Some(m) => [0, 1, 2].map(|c| each(|i| m[i][c] as f32)),
            None => [self.colour.x, self.colour.y, self.colour.z].map(|c| f32s(clamp(c))),
        };
        let (depth, l_dot_n, highlight) =
            (f32s(self.depth), f32s(self.l_dot_n), f32s(self.highlight));
        let normal = [self.normal.x, self.normal.y, self.normal.z].map(f32s);
        let records = each(|i| {
            let on = |bits: u32| bits >> i & 1 == 1;
            let colour = [colour[0][i], colour[1][i], colour[2][i]];
            let bounces = u64::from(self.reflection_rays[i]);
            let mut record = PixelRecord::missed(colour, bounces, rays[i].total());
            if on(self.hit) {
                let shaded = |x: [f32; WIDTH]| if on(self.shaded) { x[i] } else { 0.0 };
                record.set_hit(
                    depth[i],
                    [normal[0][i], normal[1][i], normal[2][i]],
                    on(self.lit),
                    self.object[i],
                    shaded(l_dot_n),
                    shaded(highlight),
                );
            }
            record
        });
        store_packet(out, &records);
    }

    /// Each lane's rays.
    #[inline(always)]
    fn rays(&self) -> [Rays; WIDTH] {
        each(|i| Rays {
            primary: 1,
            shadow: u64::from(self.shadow_rays[i]),
            reflection: u64::from(self.reflection_rays[i]),
            // Not through the book's `trace`.
            paths: 0,
        })
    }
}

/// The nearest hit of each lane so far, kept as [`scene::consider`] keeps it:
/// an object replaces the one found only when it is nearer, or as near with a
/// lower index, so that the result does not depend on the order of the tests.
///
/// [`scene::consider`]: crate::scene::consider
struct Nearest<'a, T: Laned> {
    tracer: &'a Fast<T>,
    ray: &'a Packet<T>,
    alive: u32,
    t: T::Lanes,
    which: [usize; WIDTH],
    found: T::Lanes,
}

impl<T: Laned> PacketSearch for Nearest<'_, T> {
    fn active(&self) -> u32 {
        self.alive
    }

    fn limits(&self) -> F64s {
        let none = F64s::splat(f64::INFINITY);
        F64s::mask(self.found.bits()).select(convert::<T, f64>(self.t), none)
    }

    #[inline(always)]
    fn test(&mut self, index: usize) {
        let shape = self.tracer.shape(index);
        self.consider(index, &shape);
    }

    #[inline(always)]
    fn test_sphere(&mut self, index: usize, ball: &[f64; 4]) {
        self.consider(index, &Shape4::ball(ball));
    }
}

impl<T: Laned> Nearest<'_, T> {
    /// Test object `index`, of geometry `shape`, and keep it where it is nearer.
    #[inline(always)]
    fn consider(&mut self, index: usize, shape: &Shape4<T>) {
        let (t, hit) = self.tracer.hits(shape, self.ray);
        if hit.bits() == 0 {
            return;
        }
        let mut nearer = (hit & (!self.found | t.lt(self.t))).bits();
        // A tie (two objects at one distance, which is rare) goes to the lower index.
        let tie = (hit & self.found & !t.ne(self.t)).bits();
        if tie != 0 {
            for i in lanes_of(tie) {
                if index < self.which[i] {
                    nearer |= 1 << i;
                }
            }
        }
        if nearer == 0 {
            return;
        }
        let m = T::Lanes::mask(nearer);
        self.t = m.select(t, self.t);
        for (i, which) in self.which.iter_mut().enumerate() {
            if nearer >> i & 1 == 1 {
                *which = index;
            }
        }
        self.found = self.found | m;
    }
}

/// The lanes whose shadow ray is blocked so far.
struct Blocked<'a, T: Laned> {
    tracer: &'a Fast<T>,
    ray: &'a Packet<T>,
    distance: T::Lanes,
    alive: u32,
    blocked: u32,
}

impl<T: Laned> PacketSearch for Blocked<'_, T> {
    /// The lanes not blocked yet: none, and the search stops.
    fn active(&self) -> u32 {
        self.alive & !self.blocked
    }

    fn limits(&self) -> F64s {
        convert::<T, f64>(self.distance)
    }

    #[inline(always)]
    fn test(&mut self, index: usize) {
        let shape = self.tracer.shape(index);
        self.consider(&shape);
    }

    #[inline(always)]
    fn test_sphere(&mut self, _index: usize, ball: &[f64; 4]) {
        self.consider(&Shape4::ball(ball));
    }
}

impl<T: Laned> Blocked<'_, T> {
    /// Test an object of geometry `shape`: does it stand before the light?
    #[inline(always)]
    fn consider(&mut self, shape: &Shape4<T>) {
        let (t, hit) = self.tracer.hits(shape, self.ray);
        self.blocked |= (hit & t.lt(self.distance)).bits();
    }
}

/// The lanes `bits` as indices.
#[inline(always)]
fn lanes_of(bits: u32) -> impl Iterator<Item = usize> {
    let mut left = bits & ALL;
    std::iter::from_fn(move || {
        let lane = left.trailing_zeros() as usize;
        left &= left.wrapping_sub(1);
        (lane < WIDTH).then_some(lane)
    })
}

/// Add one to `counts[i]` for each lane `i` of `bits`.
#[inline(always)]
fn count(counts: &mut [u32; WIDTH], bits: u32) {
    for (i, c) in counts.iter_mut().enumerate() {
        *c += bits >> i & 1;
    }
}

/// Put a packet's `records` into its pixels `out` (the first `out.len()` of
/// them): the same bytes as `out.copy_from_slice`. A whole packet whose pixels
/// start on a multiple of 16 bytes (every packet, where a row is a multiple of 4
/// pixels wide) is written with non-temporal stores (`movntdq`, SSE2, which
/// every x86-64 processor has): they send the bytes towards memory without
/// first reading in the cache lines they fill, as an ordinary store must. The
/// frame (108 MB at 1920 × 1080) is far larger than the caches, so each line
/// would be read only to be overwritten. `cargo bench --bench rates -- store` fills a
/// frame both ways (chapter 10). Once a row is done, [`finish_stores`] makes its
/// records visible to the other threads.
// ANCHOR: store_packet
#[inline(always)]
pub fn store_packet(out: &mut [PixelRecord], records: &[PixelRecord; WIDTH]) {
    #[cfg(target_arch = "x86_64")]
    if out.len() == WIDTH && (out.as_ptr() as usize).is_multiple_of(16) {
        use std::arch::x86_64::{__m128i, _mm_loadu_si128, _mm_stream_si128};
        const CHUNKS: usize = WIDTH * RECORD_BYTES / 16;
        const _: () = assert!(CHUNKS * 16 == std::mem::size_of::<[PixelRecord; WIDTH]>());
        let from = records.as_ptr().cast::<__m128i>();
        let to = out.as_mut_ptr().cast::<__m128i>();
        for k in 0..CHUNKS {
            // SAFETY: `records` and `out` each hold WIDTH records, CHUNKS × 16
            // bytes; `to` is 16-byte aligned (checked above), as `movntdq`
            // needs; `_mm_loadu_si128` reads any address; SSE2 is part of x86-64.
            #[allow(unsafe_code)]
            unsafe {
                _mm_stream_si128(to.add(k), _mm_loadu_si128(from.add(k)));
            }
        }
        return;
    }
    let n = out.len();
    out.copy_from_slice(&records[..n]);
}
// ANCHOR_END: store_packet

/// Order the non-temporal stores of [`store_packet`] before whatever this
/// thread does next (`sfence`), so that a thread that learns through rayon that
/// the row is done also sees its records. (Called at the end of every row.)
#[inline(always)]
pub fn finish_stores() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `sfence` is SSE, part of x86-64.
    #[allow(unsafe_code)]
    unsafe {
        std::arch::x86_64::_mm_sfence();
    }
}

impl<T: Laned> Fast<T> {
    // ANCHOR: packet
    /// The records of pixels `col`, `col + 1`, … of row `row`, one per element of
    /// `out` (at most [`WIDTH`]), traced as one packet from their primary rays `ray`
    /// ([`Fast::pixel_rays`]): what the book's [`Tracer::pixel`](crate::render::Tracer::pixel) gives for each of them, and
    /// the rays they took.
    #[inline(always)]
    pub fn pixel_packet(
        &self,
        row: u32,
        col: u32,
        ray: Packet<T>,
        out: &mut [PixelRecord],
    ) -> Rays {
        let n = out.len();
        assert!((1..=WIDTH).contains(&n), "a packet has 1 to {WIDTH} pixels");
        // The four pixels share the tile mask of the first, and the objects in lanes.
        debug_assert!(
            (col as usize).is_multiple_of(WIDTH),
            "a packet starts at a multiple of {WIDTH}"
        );
        debug_assert!(self.packets, "a fast engine made without packets");
        let lanes = ALL >> (WIDTH - n);
        let mut total = Rays::default();
        if !self.book.stages.intersection {
            let d = ray.direction.to_vectors();
            let records = each(|i| {
                let colour = direction_colour(d[i].to_f64()).clamp(Vec3::ZERO, Vec3::ONE);
                PixelRecord::new(colour, None, 0, 1)
            });
            store_packet(out, &records);
            total.primary += n as u64;
            return total;
        }
        let candidates = self.masks.mask(row, col);
        let centre = self.trace_packet(ray, lanes, candidates);
        let mut rays = centre.rays();
        let mut mean = None;
        if self.spp > 1 {
            // Several samples: the mean colour; the buffers keep the centre ray's.
            let mut sum = [Vec3::ZERO; WIDTH];
            for sample in 0..self.spp {
                let at: [(f64, f64); WIDTH] =
                    each(|i| stratified(row, self.column(col, i), sample, self.spp));
                let ray = self.rays_through(each(|i| at[i].0), each(|i| at[i].1));
                let traced = self.trace_packet(ray, lanes, candidates);
                for (i, (c, r)) in traced.colours().into_iter().zip(traced.rays()).enumerate() {
                    sum[i] += c;
                    rays[i] += r;
                }
            }
            mean = Some(each(|i| sum[i] / f64::from(self.spp)));
        }
        centre.write(mean, &rays, out);
        for r in &rays[..n] {
            total += *r;
        }
        total
    }
    // ANCHOR_END: packet

    /// The primary rays of pixels `col`, `col + 1`, … of row `row`: the packet
    /// [`Fast::pixel_packet`] traces from there. Lanes past the image's right
    /// edge repeat its last pixel (their records are dropped).
    #[inline(always)]
    pub fn pixel_rays(&self, row: u32, col: u32) -> Packet<T> {
        // The screen points, as the camera gives them: x read from its table.
        let x = T::Lanes::from_array(each(|i| self.columns[self.column(col, i) as usize]));
        let [_, y, _] = components::<T>(self.book.camera.screen_point::<T>(row, 0));
        self.rays_to(x, T::Lanes::splat(y))
    }

    /// The column of lane `i` of the packet at `col`: `col + i`, or the image's
    /// last column past its right edge.
    #[inline(always)]
    fn column(&self, col: u32, i: usize) -> u32 {
        (col + i as u32).min(self.book.camera.width - 1)
    }

    /// The rays from the eye through the screen at fractional (`rows[i]`,
    /// `cols[i]`), as [`Camera::ray_through`](crate::camera::Camera::ray_through)
    /// computes each.
    #[inline(always)]
    fn rays_through(&self, rows: [f64; WIDTH], cols: [f64; WIDTH]) -> Packet<T> {
        let camera = &self.book.camera;
        let s = &camera.screen;
        // The camera's grid, four samples at once.
        let grid = |from: f64, to: f64, at: [f64; WIDTH], n: u32| {
            let (from, to) = (T::Lanes::splat(T::of(from)), T::Lanes::splat(T::of(to)));
            lerp_on_grid(from, to, T::Lanes::from_array(each(|i| T::of(at[i]))), n)
        };
        let x = grid(s.left, s.right, cols, camera.width);
        let y = grid(s.top, s.bottom, rows, camera.height);
        self.rays_to(x, y)
    }

    /// The rays from the eye through the screen points (`x[i]`, `y[i]`, 0), as
    /// [`Ray::towards`](crate::ray::Ray::towards) makes each.
    #[inline(always)]
    fn rays_to(&self, x: T::Lanes, y: T::Lanes) -> Packet<T> {
        let origin = V3::splat(T::Vec3::of(self.book.camera.position));
        let target = V3::new(x, y, T::Lanes::splat(T::of(0.0)));
        Packet {
            origin,
            direction: (target - origin).normalize(),
        }
    }

    // ANCHOR: trace_packet
    /// The book's [`Tracer::trace`](crate::render::Tracer::trace) for the four rays of `ray`, of which the lanes `lanes`
    /// count.
    #[inline(always)]
    fn trace_packet(&self, mut ray: Packet<T>, lanes: u32, candidates: u64) -> Traced4<T> {
        let segments = if self.book.stages.reflection {
            self.book.max_depth
        } else {
            1
        };
        let mut traced = Traced4::blank();
        let mut weight = T::Lanes::splat(T::of(1.0));
        let light = V3::<T>::splat(self.book.light.position);
        let mut alive = lanes; // the lanes whose path goes on
        for segment in 0..segments {
            if segment > 0 {
                count(&mut traced.reflection_rays, alive);
            }
            // The nearest object along each ray; the lanes that find none end.
            let search = if segment == 0 { candidates } else { EVERY };
            let (t, which, found) = self.nearest_packet(&ray, alive, search);
            alive &= found;
            if alive == 0 {
                break;
            }
            let made;
            let object = match (self.book.bvh.is_some(), self.same_object(&which, alive)) {
                (false, Some(index)) => &self.packed[index],
                (false, None) => {
                    made = Packed::blend(which.map(|w| &self.packed[w]));
                    &made
                }
                // The many objects of a BVH are not kept in lanes: made for the hit
                // (read for the lanes alive only, when they hit one object).
                (true, Some(index)) => {
                    made = Packed::new(&self.book.objects[index], &self.book.light);
                    &made
                }
                (true, None) => {
                    made = Packed::gather(which.map(|w| &self.book.objects[w]), &self.book.light);
                    &made
                }
            };
            let point = ray.at(t);
            // The light's distance and the direction to the viewer, made before
            // they are needed (if they are): their square roots and divisions then
            // overlap the normal's and the shadow test's.
            let light_distance = if self.book.stages.shadow {
                Some((light - point).length())
            } else {
                None
            };
            let to_viewer = if self.book.stages.blinn_phong {
                let viewer = match self.book.viewer {
                    Viewer::Camera => V3::splat(T::Vec3::of(self.book.camera.position)),
                    Viewer::RayOrigin => ray.origin,
                };
                Some((viewer - point).normalize())
            } else {
                None
            };
            let normal = self.normal_packet(object, alive, point, &ray);
            let shifted = self.step_off_packet(object, alive, point, normal);
            let to_light = (light - shifted).normalize();

            // Shadow: the lanes whose point does not see the light end, black.
            // On a sphere's own dark side no ray is asked (`own_shadow`).
            let lit = if let Some(light_distance) = light_distance {
                let away = match self.book.offset {
                    Offset::Auto => {
                        let zero = T::Lanes::splat(T::of(0.0));
                        object.shape.spheres & normal.dot(to_light).lt(zero).bits()
                    }
                    _ => 0,
                };
                let cast = alive & !away;
                count(&mut traced.shadow_rays, cast);
                let shadow_ray = Packet {
                    origin: shifted,
                    direction: to_light,
                };
                if cast == 0 {
                    0
                } else {
                    cast & !self.blocked_packet(&shadow_ray, light_distance, cast)
                }
            } else {
                alive
            };

            // Blinn-Phong, seen from the camera (or the ray's origin), where lit.
            let terms = match to_viewer {
                Some(to_viewer) if lit != 0 => {
                    Some(self.terms_packet(object, lit, normal, to_light, to_viewer))
                }
                _ => None,
            };
            if segment == 0 {
                traced.hit = alive;
                traced.lit = lit;
                traced.depth = t;
                traced.normal = normal;
                traced.object = which;
                if let Some(terms) = &terms {
                    traced.shaded = lit;
                    (traced.l_dot_n, traced.highlight) = (terms.l_dot_n, terms.highlight);
                }
            }
            alive = lit;
            if alive == 0 {
                break;
            }
            // Without Blinn-Phong, the object's flat diffuse colour.
            let illumination = match terms {
                Some(terms) => terms.sum,
                None => object.diffuse,
            };
            // Reflection: add this segment's light, weighted, and bounce.
            let on = T::Lanes::mask(alive);
            traced.colour = V3::select(
                on,
                traced.colour + illumination.scale(weight),
                traced.colour,
            );
            weight = on.select(weight * object.reflection, weight);
            ray = Packet {
                origin: shifted,
                direction: reflect(ray.direction, normal),
            };
            // Early stop: nothing the rest of the path adds can change the pixel.
            let left = (segments - segment - 1) as usize;
            if let Some(&reach) = self.book.reach.get(left) {
                let most = convert::<T, f64>(weight) * F64s::splat(reach);
                alive &= !most.lt(F64s::splat(HALF_STEP)).bits();
                if alive == 0 {
                    break;
                }
            }
        }
        traced
    }
    // ANCHOR_END: trace_packet

    /// The object every lane of `alive` hit, if it is one. (Lanes outside `alive`
    /// hold the index of an earlier hit or 0, always a valid object.)
    #[inline(always)]
    fn same_object(&self, which: &[usize; WIDTH], alive: u32) -> Option<usize> {
        let some = which[alive.trailing_zeros() as usize];
        let same = (0..WIDTH).all(|i| alive >> i & 1 == 0 || which[i] == some);
        same.then_some(some)
    }

    // ANCHOR: nearest_packet
    /// The nearest object along each ray of the lanes `alive`: its distance and
    /// index, lane by lane, and the lanes that found one.
    #[inline(always)]
    fn nearest_packet(
        &self,
        ray: &Packet<T>,
        alive: u32,
        search: u64,
    ) -> (T::Lanes, [usize; WIDTH], u32) {
        let mut nearest = Nearest {
            tracer: self,
            ray,
            alive,
            t: T::Lanes::splat(T::of(0.0)),
            which: [0; WIDTH],
            found: T::Lanes::mask(0),
        };
        self.search_packet(ray, search, &mut nearest);
        (nearest.t, nearest.which, nearest.found.bits())
    }

    /// The lanes among `alive` whose ray meets an object closer than `distance`:
    /// the shadow test, which stops once every lane is blocked.
    #[inline(always)]
    fn blocked_packet(&self, ray: &Packet<T>, distance: T::Lanes, alive: u32) -> u32 {
        let mut blocked = Blocked {
            tracer: self,
            ray,
            distance,
            alive,
            blocked: 0,
        };
        self.search_packet(ray, EVERY, &mut blocked);
        blocked.blocked
    }

    /// Put the objects to `search`: through the BVH if there is one, else the
    /// plain loop over the objects the mask `objects` selects, lowest index first,
    /// until no lane is still searching.
    #[inline(always)]
    fn search_packet(&self, ray: &Packet<T>, objects: u64, search: &mut impl PacketSearch) {
        if let Some(bvh) = &self.book.bvh {
            return bvh.search_packet(&ray.origin, &ray.direction, search);
        }
        let mut left = objects & self.every_object();
        while left != 0 && search.active() != 0 {
            let index = left.trailing_zeros() as usize;
            left &= left - 1;
            search.test(index);
        }
    }
    // ANCHOR_END: nearest_packet

    /// The geometry of object `index`: read where it is kept in lanes (a short
    /// list), made on the spot for the many objects of a BVH.
    #[inline(always)]
    fn shape(&self, index: usize) -> Cow<'_, Shape4<T>> {
        match self.packed.get(index) {
            Some(p) => Cow::Borrowed(&p.shape),
            None => Cow::Owned(Shape4::new(&self.book.objects[index])),
        }
    }

    /// The search mask of every object.
    #[inline(always)]
    fn every_object(&self) -> u64 {
        match self.packed.len() {
            0 => 0,
            n => EVERY >> (MAX_OBJECTS - n),
        }
    }
    /// Distance along each ray to `object`, and the mask of the lanes that hit it,
    /// by the rules of [`Object::intersect`].
    ///
    /// The book's intersection tests (the sphere's, by both methods, and the
    /// plane's) written a second time: where one ray branches on Δ and on the
    /// signs of its roots, four rays need masks, and the early outs that skip the
    /// square root and the division when all four miss are most of the packets'
    /// gain on shadow and reflected rays (chapter 10). They are not the only
    /// second copy: the plane's normal ([`Fast::normal_packet`]), the sum of the
    /// Blinn-Phong terms ([`Fast::terms_packet`]) and the path loop
    /// ([`Fast::trace_packet`]) are written again too, and only the branch-free
    /// formulas (the factors of Blinn-Phong, the offsets) are the book's own
    /// generic functions. So an edit to the book's `Sphere::intersect`,
    /// `Plane::normal_towards`, `blinn_phong::terms` or `Tracer::trace` does not
    /// reach this engine: `tests/speed.rs` holds the two to the same bits, and
    /// fails until the edit is made here too. (`render` and `stages` use the
    /// book's engine unless asked, so their pictures show such an edit at once.)
    #[inline(always)]
    fn hits(&self, object: &Shape4<T>, ray: &Packet<T>) -> (T::Lanes, T::Lanes) {
        let zero = T::Lanes::splat(T::of(0.0));
        let (d, o) = (ray.direction, ray.origin);
        if object.spheres == 0 {
            let n = object.normal;
            let facing = d.dot(n);
            let t = (object.point - o).dot(n) / facing;
            let finite = t.abs().lt(T::Lanes::splat(T::of(f64::INFINITY)));
            return (t, facing.ne(zero) & t.gt(zero) & finite);
        }
        let r2 = object.radius_squared;
        let f = o - object.point;
        // ANCHOR: early_out
        let d_dot_f = d.dot(f);
        // A ray heading away from the centre (⟨d, f⟩ > 0) meets the sphere, if at
        // all, behind its origin: a miss by the rule "both crossings in front". Most
        // shadow and reflected rays leave a sphere so; if all four do, skip the rest.
        if d_dot_f.gt(zero).bits() == ALL {
            return (zero, T::Lanes::mask(0));
        }
        let (near, far, hit) = match self.book.method {
            Method::Stable => {
                let h = -d_dot_f;
                let closest = f + d.scale(h);
                let quarter_delta = r2 - closest.length_squared();
                let crosses = quarter_delta.gt(zero);
                if crosses.bits() == 0 {
                    return (zero, crosses); // every ray passes beside
                }
                // ANCHOR_END: early_out
                let root = quarter_delta.sqrt();
                let q = h + h.ge(zero).select(root, -root);
                let c = f.length_squared() - r2;
                let t1 = c / q;
                (t1.min(q), t1.max(q), crosses & q.ne(zero))
            }
            Method::Naive => {
                let two = T::Lanes::splat(T::of(2.0));
                let b = two * d_dot_f;
                let c = f.length_squared() - r2;
                let delta = b * b - T::Lanes::splat(T::of(4.0)) * c;
                let crosses = delta.gt(zero);
                if crosses.bits() == 0 {
                    return (zero, crosses);
                }
                let root = delta.sqrt();
                let (t1, t2) = ((-b + root) / two, (-b - root) / two);
                (t1.min(t2), t1.max(t2), crosses)
            }
        };
        (near, hit & near.gt(zero) & far.gt(zero))
    }

    /// The unit normal at each hit point, as [`Object::normal_at`] gives it.
    #[inline(always)]
    fn normal_packet(
        &self,
        object: &Packed<T>,
        alive: u32,
        point: V3<T>,
        ray: &Packet<T>,
    ) -> V3<T> {
        let shape = &object.shape;
        let spheres = shape.spheres & alive;
        let sphere = || outward_normal(point, shape.point);
        if spheres == alive {
            return sphere();
        }
        let n = shape.normal;
        let plane = V3::select(ray.direction.dot(n).gt(T::Lanes::splat(T::of(0.0))), -n, n);
        if spheres == 0 {
            return plane;
        }
        V3::select(T::Lanes::mask(spheres), sphere(), plane)
    }

    /// [`step_off`](crate::shade::shadow::step_off) for each lane.
    #[inline(always)]
    fn step_off_packet(
        &self,
        object: &Packed<T>,
        alive: u32,
        point: V3<T>,
        normal: V3<T>,
    ) -> V3<T> {
        match self.book.offset {
            Offset::Fixed(step) => point + normal.scale(T::Lanes::splat(T::of(step))),
            Offset::Auto => {
                let shape = &object.shape;
                let spheres = shape.spheres & alive;
                let u = T::Lanes::splat(T::UNIT_ROUNDOFF);
                let sphere = || sphere_step(point, normal, shape.point, object.radius, u);
                if spheres == alive {
                    return sphere();
                }
                let on_surface = on_plane(point, shape.point, shape.normal);
                let plane = step_out(on_surface, normal, plane_height(on_surface, shape.point, u));
                if spheres == 0 {
                    plane
                } else {
                    V3::select(T::Lanes::mask(spheres), sphere(), plane)
                }
            }
            Offset::Scene => {
                let shape = &object.shape;
                let spheres = shape.spheres & alive;
                let sphere = || on_sphere(shape.point, normal, object.radius);
                let on_surface = if spheres == alive {
                    sphere()
                } else {
                    let plane = on_plane(point, shape.point, shape.normal);
                    if spheres == 0 {
                        plane
                    } else {
                        V3::select(T::Lanes::mask(spheres), sphere(), plane)
                    }
                };
                let u = T::Lanes::splat(T::UNIT_ROUNDOFF);
                step_out_by_scene(on_surface, normal, object.magnitude, u)
            }
        }
    }

    /// [`blinn_phong::terms`](crate::shade::blinn_phong::terms) for each lane.
    #[inline(always)]
    fn terms_packet(
        &self,
        object: &Packed<T>,
        lit: u32,
        normal: V3<T>,
        to_light: V3<T>,
        to_viewer: V3<T>,
    ) -> Terms4<T> {
        let (l_dot_n, n_dot_h) = factors(normal, to_light, to_viewer);
        // blinn_phong::power: repeated squaring for a whole exponent, powf otherwise.
        let mut highlight = powi::<T>(n_dot_h, object.whole);
        if object.fractional & lit != 0 {
            let (x, e, mut h) = (
                n_dot_h.to_array(),
                object.exponent.to_array(),
                highlight.to_array(),
            );
            for i in (0..WIDTH).filter(|i| (object.fractional & lit) >> i & 1 == 1) {
                h[i] = x[i].powf(e[i]);
            }
            highlight = T::Lanes::from_array(h);
        }
        let diffuse = object.diffuse_light.scale(l_dot_n);
        let specular = object.specular_light.scale(highlight);
        Terms4 {
            sum: object.ambient + diffuse + specular,
            l_dot_n,
            highlight,
        }
    }
}

/// Blinn-Phong's terms in each lane: their sum, and the factors the buffers keep.
struct Terms4<T: Laned> {
    sum: V3<T>,
    l_dot_n: T::Lanes,
    highlight: T::Lanes,
}
