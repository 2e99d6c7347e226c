//! `raystep bench`: how fast a frame renders, against a yardstick, in one run.
//!
//! Up to four things are timed (five where the render builds a BVH: its build alone
//! too), their runs interleaved so that a noisy machine slows all of them alike:
//! the engine asked for (`--engine`, default `fast`) with the threads asked for
//! and with one thread, the other engine with the threads asked for, and the
//! [yardstick](crate::tools::yardstick) (the tutorial's program ported plainly)
//! with the same threads. Each is rendered once to warm up, then `runs` times;
//! the median of the runs is reported. Only the render is timed:
//! the frame is allocated once, before the runs, and no file is written. Within
//! each frame of the engine asked for, its rows are timed apart from the set-up
//! before them (objects converted, BVH built), as a peer such as Embree times
//! its frames without its tree's build.

use std::cell::{Cell, RefCell};
use std::sync::Mutex;
use std::time::Instant;

use serde::Serialize;

use crate::aov::{Frame, Packets, Rays};
use crate::bvh::Bvh;
use crate::engine::render_into;
use crate::error::Error;
use crate::real::Precision;
use crate::render::{Progress, Settings};
use crate::scene::{Role, Scene};
use crate::stages::Engine;
use crate::tools::yardstick::Yardstick;

/// What `raystep bench` reports (its `--json` output).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Threads raystep and the yardstick rendered with.
    pub threads: usize,
    /// Timed runs of each measurement.
    pub runs: usize,
    /// The engine the figures below are of: `"fast"` (the default) or `"book"`.
    pub engine: &'static str,
    /// Median seconds per frame, render only, with `threads` threads.
    pub median_s: f64,
    /// Rays per frame, all kinds.
    pub rays: u64,
    /// Rays per frame from the camera.
    pub rays_primary: u64,
    /// Rays per frame towards the light.
    pub rays_shadow: u64,
    /// Rays per frame in mirrored directions.
    pub rays_reflection: u64,
    /// `rays / median_s`.
    pub rays_per_s: f64,
    /// `width · height / median_s`.
    pub pixels_per_s: f64,
    /// Median seconds of the rows alone, from the first row's start to the last
    /// row's end: the frame without the engine's set-up (objects converted, BVH
    /// built) and what follows the rows. Embree's frames are timed so.
    pub trace_s: f64,
    /// `rays / trace_s`.
    pub trace_rays_per_s: f64,
    /// Median seconds of the set-up and what follows the rows: the frame's time
    /// less its rows' time, run by run.
    pub setup_s: f64,
    /// Median seconds per frame with one thread (null when `threads` is 1).
    pub one_thread_median_s: Option<f64>,
    /// `one_thread_median_s / median_s`.
    pub thread_speedup: Option<f64>,
    /// Median seconds of the rows alone with one thread (null when `threads`
    /// is 1).
    pub one_thread_trace_s: Option<f64>,
    /// `one_thread_trace_s / trace_s`: the rows' own speed-up.
    pub trace_thread_speedup: Option<f64>,
    /// Median seconds per frame of the yardstick (null for a scene with a true
    /// plane, which the tutorial's program cannot draw, or with `--no-yardstick`).
    pub yardstick_median_s: Option<f64>,
    /// Rays per frame of the yardstick, counted per pixel and summed after the
    /// frame (its paths are the tutorial's: no early stop).
    pub yardstick_rays: Option<u64>,
    /// `yardstick_rays / yardstick_median_s`.
    pub yardstick_rays_per_s: Option<f64>,
    /// `yardstick_median_s / median_s`: how many times faster raystep is.
    pub yardstick_ratio: Option<f64>,
    /// The other engine (`"book"`, or `"fast"` under `--engine book`).
    pub other_engine: &'static str,
    /// Its median seconds per frame with `threads` threads.
    pub other_median_s: f64,
    /// `yardstick_median_s / other_median_s`.
    pub other_yardstick_ratio: Option<f64>,
    /// Median seconds to build the BVH over the scene's spheres with `threads`
    /// threads, timed in turn with the renders (null when the render uses no
    /// BVH). The render's own build is part of `median_s`.
    pub bvh_build_s: Option<f64>,
    /// Nodes of that BVH.
    pub bvh_nodes: Option<usize>,
    /// Peak resident memory of the process so far, in bytes (Linux only).
    pub peak_memory_bytes: Option<u64>,
    /// The build of the fast engine's packet loop in this run (whichever of the two
    /// timed engines it is): `"avx"` (four float64 lanes to a register),
    /// `"baseline"` (two, as on any x86-64 processor: SSE2), or `"off"` when the
    /// fast engine left the scene to the book's row loop (more than 64 objects
    /// without a BVH, or a stage it does not know).
    pub packets: &'static str,
}

/// How to bench.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Timed runs of each measurement (after one warm-up run).
    pub runs: usize,
    /// Threads for raystep and the yardstick.
    pub threads: usize,
    /// Time the yardstick too.
    pub yardstick: bool,
}

/// A timed thing: a name for messages and a closure that renders one frame.
type Job<'a> = Box<dyn FnMut() + 'a>;

/// The progress of a timed render: it keeps when its rows began and ended, and
/// adds the rows' seconds to `rows` at the end of each frame.
#[derive(Default)]
pub(crate) struct RowClock {
    began: Mutex<Option<Instant>>,
    rows: Mutex<Vec<f64>>,
}

impl Progress for RowClock {
    fn row_done(&self) {}
    fn rows_begin(&self) {
        *self.began.lock().expect("a clock is never poisoned") = Some(Instant::now());
    }
    fn rows_end(&self) {
        let began = self.began.lock().expect("a clock is never poisoned").take();
        if let Some(began) = began {
            let seconds = began.elapsed().as_secs_f64();
            self.rows
                .lock()
                .expect("a clock is never poisoned")
                .push(seconds);
        }
    }
}

impl RowClock {
    /// The rows' seconds of every frame but the first (the warm-up).
    pub(crate) fn timed(self) -> Vec<f64> {
        let rows = self.rows.into_inner().expect("a clock is never poisoned");
        rows.into_iter().skip(1).collect()
    }
}

/// Bench `scene` under `settings`. `progress(1)` is called after every run.
pub fn bench(
    scene: &Scene,
    settings: &Settings,
    options: Options,
    progress: &dyn Fn(u64),
) -> Result<Report, Error> {
    let pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| Error::Usage(format!("cannot start {threads} threads: {e}")))
    };
    let (many, one) = (pool(options.threads)?, pool(1)?);
    let yardstick = options.yardstick.then(|| Yardstick::new(scene)).flatten();

    let other = Settings {
        engine: match settings.engine {
            Engine::Book => Engine::Fast,
            Engine::Fast => Engine::Book,
        },
        ..*settings
    };
    // The tree the render builds, timed on its own too (from the objects in the
    // render's precision).
    let uses = uses_bvh(scene, settings);
    let tree = uses.then(|| scene.objects_in_play::<f64>(settings.stages));
    let tree32 = (uses && settings.precision == Precision::F32)
        .then(|| scene.objects_in_play::<f32>(settings.stages));
    let nodes = Cell::new(0);
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    // The other engine and the one-thread run take turns with one more frame (the
    // jobs run one after another); what the fast engine's packets were is noted
    // as it renders.
    let spare = RefCell::new(frame.clone());
    let fast_packets = Cell::new(Packets::Off);
    let (mut image, mut yardstick_rays) = (Vec::new(), Vec::new());
    let yardstick_total = Cell::new(0);
    let (clock, one_clock) = (RowClock::default(), RowClock::default());
    let mut jobs: Vec<Job> = vec![
        Box::new(|| many.install(|| render_into(scene, settings, &mut frame, &clock))),
        Box::new(|| {
            let mut guard = spare.borrow_mut();
            let spare: &mut Frame = &mut guard;
            many.install(|| render_into(scene, &other, spare, &|_| {}));
            if spare.engine == Engine::Fast {
                fast_packets.set(spare.packets);
            }
        }),
    ];
    if options.threads > 1 {
        jobs.push(Box::new(|| {
            let mut guard = spare.borrow_mut();
            let spare: &mut Frame = &mut guard;
            one.install(|| render_into(scene, settings, spare, &one_clock))
        }));
    }
    if let Some(y) = &yardstick {
        jobs.push(Box::new(|| {
            yardstick_total.set(many.install(|| y.render_into(&mut image, &mut yardstick_rays)))
        }));
    }
    if let Some(objects) = &tree {
        jobs.push(Box::new(|| {
            let count = many.install(|| match &tree32 {
                Some(objects) => Bvh::build(objects).node_count(),
                None => Bvh::build(objects).node_count(),
            });
            nodes.set(count);
        }));
    }
    let mut seconds = vec![Vec::with_capacity(options.runs); jobs.len()];
    for run in 0..=options.runs {
        // Each run starts with the next job, so none is always first or last.
        let count = jobs.len();
        for k in 0..count {
            let j = (run + k) % count;
            let start = Instant::now();
            jobs[j]();
            if run > 0 {
                seconds[j].push(start.elapsed().as_secs_f64());
            }
        }
        progress(1);
    }
    drop(jobs);
    let rays: Rays = frame.rays;
    let packets = match frame.engine {
        Engine::Fast => frame.packets,
        Engine::Book => fast_packets.get(),
    };

    // The rows' times, and the rest of each frame run by run.
    let (rows, one_rows) = (clock.timed(), one_clock.timed());
    let setup_s = median(seconds[0].iter().zip(&rows).map(|(f, r)| f - r).collect());
    let trace_s = median(rows);
    let one_thread_trace_s = (options.threads > 1).then(|| median(one_rows));
    let mut medians = seconds.into_iter().map(median);
    let median_s = medians.next().expect("raystep is always timed");
    let other_median_s = medians.next().expect("both engines are always timed");
    let one_thread_median_s = (options.threads > 1).then(|| medians.next()).flatten();
    let yardstick_median_s = yardstick.is_some().then(|| medians.next()).flatten();
    let bvh_build_s = tree.is_some().then(|| medians.next()).flatten();
    let pixels = f64::from(scene.width) * f64::from(scene.height);
    Ok(Report {
        width: scene.width,
        height: scene.height,
        threads: options.threads,
        runs: options.runs,
        engine: settings.engine.name(),
        median_s,
        rays: rays.total(),
        rays_primary: rays.primary,
        rays_shadow: rays.shadow,
        rays_reflection: rays.reflection,
        rays_per_s: rays.total() as f64 / median_s,
        pixels_per_s: pixels / median_s,
        trace_s,
        trace_rays_per_s: rays.total() as f64 / trace_s,
        setup_s,
        one_thread_median_s,
        thread_speedup: one_thread_median_s.map(|t| t / median_s),
        one_thread_trace_s,
        trace_thread_speedup: one_thread_trace_s.map(|t| t / trace_s),
        yardstick_median_s,
        yardstick_rays: yardstick_median_s.map(|_| yardstick_total.get()),
        yardstick_rays_per_s: yardstick_median_s.map(|t| yardstick_total.get() as f64 / t),
        yardstick_ratio: yardstick_median_s.map(|t| t / median_s),
        other_engine: other.engine.name(),
        other_median_s,
        other_yardstick_ratio: yardstick_median_s.map(|t| t / other_median_s),
        bvh_build_s,
        bvh_nodes: bvh_build_s.map(|_| nodes.get()),
        peak_memory_bytes: peak_memory_bytes(),
        packets: packets.name(),
    })
}

/// Does a render of `scene` under `settings` build a BVH? (As `Tracer::new`
/// decides, by [`Accel::builds_bvh`].)
fn uses_bvh(scene: &Scene, settings: &Settings) -> bool {
    let spheres = scene
        .objects
        .iter()
        .filter(|o| o.role == Role::Sphere)
        .count();
    settings.accel.builds_bvh(spheres, settings.method)
}

/// The median of some times (the mean of the middle two for an even count).
pub fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    let n = times.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        times[n / 2]
    } else {
        (times[n / 2 - 1] + times[n / 2]) / 2.0
    }
}

/// The peak resident memory of this process, from `/proc/self/status` (`VmHWM`;
/// `None` where there is no `/proc`). Not `getrusage`'s `ru_maxrss`, portable as
/// it is: Linux carries it over `execve` from the program the process was
/// before, so raystep started by a larger process (a test harness, a script)
/// would report that one's peak. Python allocating 500 MiB and then exec'ing a
/// small Python that reads both: `ru_maxrss` 520,204 KiB, `VmHWM` 8,128 KiB.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

impl Report {
    /// The report as a person reads it.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let mut line = |s: String| {
            out.push_str(&s);
            out.push('\n');
        };
        line(format!(
            "{} × {}, {}, median of {} run{}",
            self.width,
            self.height,
            count_threads(self.threads),
            self.runs,
            if self.runs == 1 { "" } else { "s" }
        ));
        line(format!(
            "  {:<11} {:>9.4} s per frame   {:>7.1} Mpixel/s   {:>7.1} Mray/s",
            format!("{} engine", self.engine),
            self.median_s,
            self.pixels_per_s / 1e6,
            self.rays_per_s / 1e6
        ));
        line(format!(
            "  rows alone  {:>9.4} s per frame   {:>7.1} Mray/s   (set-up and the rest {:.4} s)",
            self.trace_s,
            self.trace_rays_per_s / 1e6,
            self.setup_s
        ));
        line(format!(
            "  rays        {:>9} per frame: {} primary, {} shadow, {} reflection",
            self.rays, self.rays_primary, self.rays_shadow, self.rays_reflection
        ));
        line(format!(
            "  packets     {}",
            match self.packets {
                "avx" => "four rays at once, the AVX build (4 float64 lanes to a register)",
                "baseline" =>
                    "four rays at once, the baseline build (2 float64 lanes to a register)",
                _ =>
                    "off: the fast engine left this scene to the book's engine, one ray at a \
                      time (more than 64 objects without a BVH, or a stage it does not know)",
            }
        ));
        if let (Some(t), Some(s)) = (self.one_thread_median_s, self.thread_speedup) {
            line(format!(
                "  1 thread    {t:>9.4} s per frame   {} threads are {s:.2}× as fast",
                self.threads
            ));
            if let (Some(t), Some(s)) = (self.one_thread_trace_s, self.trace_thread_speedup) {
                line(format!(
                    "  1 thread    {t:>9.4} s of rows      {} threads are {s:.2}× as fast on the rows",
                    self.threads
                ));
            }
        }
        line(format!(
            "  {:<11} {:>9.4} s per frame   {:>7.1} Mpixel/s",
            format!("{} engine", self.other_engine),
            self.other_median_s,
            f64::from(self.width) * f64::from(self.height) / self.other_median_s / 1e6,
        ));
        match (self.yardstick_median_s, self.yardstick_ratio) {
            (Some(t), Some(r)) => {
                line(format!(
                    "  yardstick   {t:>9.4} s per frame   {:>7.1} Mpixel/s   {:>7.1} Mray/s   \
                     (the tutorial's program ported plainly, {})",
                    f64::from(self.width) * f64::from(self.height) / t / 1e6,
                    self.yardstick_rays_per_s.unwrap_or(f64::NAN) / 1e6,
                    count_threads(self.threads)
                ));
                let other = self.other_yardstick_ratio.unwrap_or(f64::NAN);
                line(format!(
                    "  speed ratio {:>9.2} {} engine, {other:.2} {} engine (each engine's speed \
                     over the yardstick's)",
                    r, self.engine, self.other_engine
                ));
            }
            _ => {
                line("  yardstick   not run (a scene with a true plane, or --no-yardstick)".into())
            }
        }
        if let (Some(t), Some(n)) = (self.bvh_build_s, self.bvh_nodes) {
            line(format!(
                "  BVH build   {t:>9.4} s ({n} nodes, {}; part of each frame's time)",
                count_threads(self.threads)
            ));
        }
        if let Some(bytes) = self.peak_memory_bytes {
            line(format!("  peak memory {:>9.1} MB", bytes as f64 / 1e6));
        }
        out
    }
}

/// "1 thread", "2 threads".
fn count_threads(n: usize) -> String {
    format!("{n} thread{}", if n == 1 { "" } else { "s" })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The peak is at least what is resident now (read before it: the peak can
    /// only rise), which includes memory just written. (Other tests run beside
    /// this one, so nothing sharper holds.)
    #[cfg(target_os = "linux")]
    #[test]
    fn the_peak_memory_holds_what_is_resident() {
        let size = 64 << 20;
        let written = std::hint::black_box(vec![1u8; size]);
        let status = std::fs::read_to_string("/proc/self/status").unwrap();
        let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
        let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
        let resident = kib * 1024;
        let peak = peak_memory_bytes().expect("/proc/self/status");
        assert!(resident >= size as u64, "{resident}");
        assert!(peak >= resident, "peak {peak}, resident {resident}");
        drop(written);
    }

    #[test]
    fn the_median_takes_the_middle() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(vec![]).is_nan());
    }

    /// The row clock keeps the rows' time of every frame but the first, the
    /// warm-up: three frames, two times.
    #[test]
    fn the_row_clock_leaves_out_the_warm_up_frame() {
        let clock = RowClock::default();
        for _ in 0..3 {
            clock.rows_begin();
            clock.rows_end();
        }
        // A frame whose rows never began (an interrupted one) adds no time.
        clock.rows_end();
        assert_eq!(clock.timed().len(), 2);
    }
}
