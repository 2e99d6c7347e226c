//! How many float64 square roots and divisions this processor finishes a second,
//! one at a time and four lanes at a time: `cargo bench --bench rates`.
//!
//! The packet tracer's speed-up over one ray at a time is bounded by these rates
//! where its chains of square roots and divisions keep the divider busy
//! (chapter 10). Each bench runs twenty-four independent chains (`x ← √(x + 1)` or
//! `x ← 3 / (x + 1)`), enough to keep the unit full rather than wait on one
//! result, and counts the lanes computed: divan's "item/s" is the rate. The
//! four-lane runs are the AVX instructions `vsqrtpd` and `vdivpd` on 256-bit
//! registers, written with `std::arch` (the same instructions the packet loop's
//! AVX build is made of); where the processor has no AVX they are skipped.
//!
//! The other thing every frame must do, whatever it computes, is store its
//! records: `store_records_*` fills a 1920 × 1080 frame of [`PixelRecord`]s
//! (52 bytes each, 108 MB) that was written before, as `bench` reuses its frame,
//! on one thread and on rayon's pool (one thread a core), a row a task as the
//! engines do, one record at a time as the book engine stores them;
//! `store_packets_*` the same, four records at a time through the fast engine's
//! own `store_packet` (non-temporal stores). divan's "B/s" is the rate; the time
//! is a frame's store floor.

use divan::counter::{BytesCount, ItemsCount};
use divan::Bencher;
use rayon::prelude::*;
use raystep::aov::{PixelRecord, RECORD_BYTES};
use raystep::fast::lanes::WIDTH as LANES;
use raystep::fast::packet::{finish_stores, store_packet};
use std::hint::black_box;

fn main() {
    divan::main();
}

/// Steps of each chain a bench iteration.
const STEPS: usize = 10_000;
/// Independent chains.
const CHAINS: usize = 24;

/// `f` applied `STEPS` times along each of `CHAINS` chains of one number each.
/// [`opaque`] on every value keeps the compiler from putting two chains in one
/// SIMD register: these are the scalar instructions `sqrtsd` and `divsd`.
#[inline(always)]
fn scalar(f: impl Fn(f64) -> f64) -> f64 {
    let mut x = [1.5f64; CHAINS];
    for _ in 0..STEPS {
        for v in &mut x {
            *v = opaque(f(*v));
        }
    }
    x.iter().sum()
}

/// `x`, through a step the compiler cannot see into, in a register.
///
/// `black_box` on the value going in did not do: the compiler paired the square
/// roots of two chains into one two-lane `sqrtpd`, and the "one lane" rate was
/// two lanes' worth. `black_box` going out as well did, but it passes the value
/// through memory, three stores a step, and those, not the divider, then set
/// the divisions' rate (0.43 G a second against 0.80 G on an AMD EPYC).
/// An empty `asm!` that names the value's register costs nothing and hides it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn opaque(mut x: f64) -> f64 {
    // SAFETY: the block is empty: it reads and writes nothing but `x`'s
    // register, which it leaves as it was.
    unsafe {
        std::arch::asm!("/* {0} */", inout(xmm_reg) x, options(nomem, nostack, preserves_flags));
    }
    x
}

/// `x`, through `black_box` where there is no `asm!` for it above. The value
/// then goes through memory each step, and there the one-lane rates may be
/// set by those stores rather than by the divider.
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn opaque(x: f64) -> f64 {
    black_box(x)
}

/// Time `run`, which computes `lanes` lanes at every step of every chain: the
/// rate is in lanes a second.
fn rate(bencher: Bencher, lanes: usize, run: impl Fn() -> f64 + Sync) {
    bencher
        .counter(ItemsCount::new(STEPS * CHAINS * lanes))
        .bench(run);
}

#[divan::bench]
fn sqrt_one_lane(bencher: Bencher) {
    rate(bencher, 1, || scalar(|x| (x + 1.0).sqrt()));
}

#[divan::bench]
fn div_one_lane(bencher: Bencher) {
    rate(bencher, 1, || scalar(|x| 3.0 / (x + 1.0)));
}

/// The frame `store_records_*` fills: 1920 × 1080.
const WIDTH: usize = 1920;
const HEIGHT: usize = 1080;

/// The record of pixel `x` of row `row`: records differ from pixel to pixel,
/// so that no store can be left out or merged.
#[inline(always)]
fn record(row: usize, x: usize) -> PixelRecord {
    let v = (row * WIDTH + x) as f32;
    let mut r = PixelRecord::missed([v, v + 1.0, v + 2.0], 1, 2);
    r.set_hit(v, [v, -v, 0.5], x.is_multiple_of(2), x, 0.25, v * 0.5);
    r
}

/// Fill `line` (row `row`) record by record.
fn fill_row(row: usize, line: &mut [PixelRecord]) {
    for (x, pixel) in line.iter_mut().enumerate() {
        *pixel = record(row, x);
    }
}

/// Fill `line` (row `row`) a packet at a time, as the fast engine does.
fn fill_row_in_packets(row: usize, line: &mut [PixelRecord]) {
    for (p, packet) in line.chunks_mut(LANES).enumerate() {
        let records = std::array::from_fn(|i| record(row, p * LANES + i));
        store_packet(packet, &records);
    }
    finish_stores();
}

/// Time filling a frame, its pages already touched: `fill` on every row, one
/// after another on this thread, or on all of rayon's threads a row a task.
fn store_frame(bencher: Bencher, fill: fn(usize, &mut [PixelRecord]), all_threads: bool) {
    let rows = |frame: &mut [PixelRecord]| match all_threads {
        true => frame
            .par_chunks_mut(WIDTH)
            .with_max_len(1)
            .enumerate()
            .for_each(|(row, line)| fill(row, line)),
        false => (frame.chunks_mut(WIDTH).enumerate()).for_each(|(row, line)| fill(row, line)),
    };
    let mut frame = vec![PixelRecord::missed([0.0; 3], 0, 0); WIDTH * HEIGHT];
    rows(&mut frame);
    bencher
        .counter(BytesCount::new(WIDTH * HEIGHT * RECORD_BYTES))
        .bench_local(|| rows(black_box(&mut frame)));
}

#[divan::bench]
fn store_records_one_thread(bencher: Bencher) {
    store_frame(bencher, fill_row, false);
}

#[divan::bench]
fn store_records_all_threads(bencher: Bencher) {
    store_frame(bencher, fill_row, true);
}

#[divan::bench]
fn store_packets_one_thread(bencher: Bencher) {
    store_frame(bencher, fill_row_in_packets, false);
}

#[divan::bench]
fn store_packets_all_threads(bencher: Bencher) {
    store_frame(bencher, fill_row_in_packets, true);
}

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::*;
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_div_pd, _mm256_set1_pd, _mm256_sqrt_pd, _mm256_storeu_pd,
    };

    /// `f` applied `STEPS` times along each of `CHAINS` chains of four lanes.
    #[inline(always)]
    unsafe fn lanes(f: impl Fn(__m256d) -> __m256d) -> f64 {
        let mut x = [_mm256_set1_pd(1.5); CHAINS];
        for _ in 0..STEPS {
            for v in &mut x {
                *v = f(*v);
            }
        }
        let mut sum = 0.0;
        for v in x {
            let mut lanes = [0.0; 4];
            _mm256_storeu_pd(lanes.as_mut_ptr(), v);
            sum += lanes.iter().sum::<f64>();
        }
        sum
    }

    #[target_feature(enable = "avx")]
    unsafe fn sqrt4() -> f64 {
        lanes(|x| _mm256_sqrt_pd(_mm256_add_pd(x, _mm256_set1_pd(1.0))))
    }

    #[target_feature(enable = "avx")]
    unsafe fn div4() -> f64 {
        lanes(|x| _mm256_div_pd(_mm256_set1_pd(3.0), _mm256_add_pd(x, _mm256_set1_pd(1.0))))
    }

    /// [`rate`] of `run`, four lanes a step, where the processor has AVX (the
    /// fast engine's own check); skipped elsewhere.
    fn four_lanes(bencher: Bencher, run: unsafe fn() -> f64) {
        if raystep::fast::packet::has_avx() {
            // SAFETY: the processor has AVX (checked above), all `run` needs.
            rate(bencher, 4, || unsafe { run() });
        }
    }

    #[divan::bench]
    fn sqrt_four_lanes_avx(bencher: Bencher) {
        four_lanes(bencher, sqrt4);
    }

    #[divan::bench]
    fn div_four_lanes_avx(bencher: Bencher) {
        four_lanes(bencher, div4);
    }
}
