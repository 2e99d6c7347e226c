//! The fast engine (`--engine fast`): the book's tracer, four rays at a time.
//!
//! It is built on the book's [`Tracer`](crate::render::Tracer) and reads everything from it: the objects,
//! the light, the rules, the BVH. What it adds never changes a pixel: rays traced
//! four at a time in SIMD lanes ([`crate::fast::packet`]), tile masks that skip objects
//! a tile's primary rays cannot hit ([`TileMasks`](masks::TileMasks)), a packet walk of the
//! BVH, and records stored without first reading in the memory they overwrite
//! ([`store_packet`](packet::store_packet)). `tests/speed.rs` holds it to the
//! book's bits on every scene and setting.
//! The book's files never import this one.
//!
//! What it does not take in packets (more than [`MAX_OBJECTS`](crate::fast::packet::MAX_OBJECTS) objects without
//! a BVH, or a stage the packet loop does not know), it traces with the book's own
//! row loop, and says so in the frame
//! ([`Frame::packets`] is then `off`).

pub mod lanes;
pub mod masks;
pub mod packet;
pub mod walk;

use crate::aov::{Frame, Packets, PixelRecord, Rays};
use crate::fast::lanes::{Laned, WIDTH};
pub use crate::fast::packet::Fast;
use crate::fast::packet::BATCH;
use crate::real::Precision;
use crate::render::{book_row, in_rows, Progress, Settings};
use crate::scene::Scene;
use crate::stages::Engine;

impl<T: Laned> Fast<T> {
    // ANCHOR: packet_row
    /// The records of row `row`, four pixels at a time ([`Fast::pixel_packet`]),
    /// into `line`, and the rays they took.
    ///
    /// The packet tracer is compiled twice: for any x86-64 processor (SSE2: two
    /// float64 lanes to a register), and for one with AVX (four). Which one runs
    /// was decided in [`Fast::new`] (`self.avx`: `--avx`, and what the processor
    /// says it has). Both compute every
    /// lane with the same IEEE operations in the same order, so they give the same
    /// bits; only the number of instructions differs.
    pub fn packet_row(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is true only where the processor has AVX (`has_avx`).
            #[allow(unsafe_code)]
            return unsafe { self.packet_row_avx(row, line) };
        }
        self.packet_row_baseline(row, line)
    }
    // ANCHOR_END: packet_row

    /// [`Fast::packet_row_in_lanes`] compiled for any processor of the target.
    /// (A function of its own, so that `packet_row`'s frame holds only one of the
    /// two builds' variables: unoptimised (`opt-level = 0`), where they are not
    /// packed, each build's frame is about 1.2 MB, two of them more than a 2 MB
    /// thread stack; at the `opt-level = 1` of the project's debug builds, about
    /// 7 kB. Measured from the stack adjustment at the start of `packet_row_avx`,
    /// `objdump -d`.)
    #[inline(never)]
    fn packet_row_baseline(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        self.packet_row_in_lanes(row, line)
    }

    /// [`Fast::packet_row_in_lanes`] compiled for AVX: everything it calls is
    /// inlined into it, and so compiled for AVX too.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[allow(unsafe_code)]
    unsafe fn packet_row_avx(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        self.packet_row_in_lanes(row, line)
    }

    /// The loop of [`Fast::packet_row`], for whichever build calls it.
    #[inline(always)]
    fn packet_row_in_lanes(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        let mut rays = Rays::default();
        // The primary rays of a few packets are made before any of them is traced.
        // Each direction waits on a square root and a division; made one after the
        // other they overlap, where made just before its packet each would hold up
        // everything after it.
        for (b, batch) in line.chunks_mut(WIDTH * BATCH).enumerate() {
            let first = (b * WIDTH * BATCH) as u32;
            let mut primary = [self.pixel_rays(row, first); BATCH];
            for (k, packet) in primary.iter_mut().enumerate().skip(1) {
                *packet = self.pixel_rays(row, first + (k * WIDTH) as u32);
            }
            for (k, pixels) in batch.chunks_mut(WIDTH).enumerate() {
                rays += self.pixel_packet(row, first + (k * WIDTH) as u32, primary[k], pixels);
            }
        }
        crate::fast::packet::finish_stores();
        rays
    }

    /// The records of row `row` into `line` and the rays they took: in packets,
    /// or by the book's row loop for what the packets do not take.
    pub fn row(&self, row: u32, line: &mut [PixelRecord]) -> Rays {
        match self.packets {
            true => self.packet_row(row, line),
            false => book_row(&self.book, self.spp, row, line),
        }
    }
}

/// Render `scene` under `settings` with the fast engine into `frame` (of the
/// scene's size), telling `progress` of each row finished (from any thread).
pub fn render_into(scene: &Scene, settings: &Settings, frame: &mut Frame, progress: &dyn Progress) {
    match settings.precision {
        Precision::F32 => render_in(
            &Fast::<f32>::new(scene, settings),
            scene,
            settings,
            frame,
            progress,
        ),
        Precision::F64 => render_in(
            &Fast::<f64>::new(scene, settings),
            scene,
            settings,
            frame,
            progress,
        ),
    }
}

/// [`render_into`] by `fast`: rows in parallel.
fn render_in<T: Laned>(
    fast: &Fast<T>,
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &dyn Progress,
) {
    let width = scene.width as usize;
    assert_eq!(frame.pixels.len(), width * scene.height as usize);
    let rays = in_rows(frame, width, progress, |row, line| fast.row(row, line));
    frame.describe(scene, &fast.book, settings, rays);
    frame.engine = Engine::Fast;
    frame.packets = match (fast.packets, fast.avx) {
        (false, _) => Packets::Off,
        (true, false) => Packets::Baseline,
        (true, true) => Packets::Avx,
    };
}
