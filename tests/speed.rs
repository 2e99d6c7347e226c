//! What the speed work promises: the fast paths change no pixel, the yardstick is
//! the tutorial's program, rays are counted right, samples and early stop do what
//! they say, and the pixel loop allocates nothing. (Speed itself is measured by
//! `raystep bench` and `cargo bench`, never here.)

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use raystep::accel::Accel;
use raystep::aov::{Frame, Packets, PixelRecord, Rays};
use raystep::engine::render;
use raystep::fast::packet::has_avx;
use raystep::fast::Fast;
use raystep::real::Precision;
use raystep::render::{book_row, Settings};
use raystep::samples::stratified;
use raystep::scene::Scene;
use raystep::sphere::Method;
use raystep::stages::{Engine, Stages};
use raystep::tools::yardstick::Yardstick;

/// Counts the allocations made by the current thread while `COUNTING` is set.
struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: every call is passed on to the system allocator unchanged; the counter
// only reads and writes thread-local cells, which do not allocate once created.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.with(|a| a.set(a.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.with(|a| a.set(a.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn load(path: &str, width: u32, height: u32) -> Scene {
    let mut scene = raystep::io::scene_file::load(std::path::Path::new(path)).unwrap();
    (scene.width, scene.height) = (width, height);
    scene
}

fn scenes() -> Vec<(String, Scene)> {
    let mut all = vec![("seed".to_string(), common::seed(160, 90))];
    for dir in ["scenes", "scenes/stress"] {
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        for p in paths {
            all.push((p.display().to_string(), load(p.to_str().unwrap(), 96, 64)));
        }
    }
    let mut many = raystep::tools::generate::scene(60, 5);
    (many.width, many.height) = (160, 90);
    all.push(("60 generated spheres".into(), many));
    all
}

#[test]
fn tile_masks_and_the_bvh_change_no_pixel_of_any_scene() {
    // The book engine asks the BVH; the fast one the tile masks and the BVH's
    // packet walk.
    let both =
        |base: Settings| [Engine::Book, Engine::Fast].map(|engine| Settings { engine, ..base });
    for (name, scene) in scenes() {
        for base in both(Settings::from(Stages::ALL))
            .into_iter()
            .chain(both(Settings::tutorial(Stages::ALL)))
        {
            let frames: Vec<Frame> = [Accel::Off, Accel::Auto, Accel::Bvh]
                .into_iter()
                .map(|accel| render(&scene, &Settings { accel, ..base }, &|_| {}))
                .collect();
            for (frame, accel) in frames[1..].iter().zip(["auto", "bvh"]) {
                assert!(
                    frame.pixels == frames[0].pixels && frame.rays == frames[0].rays,
                    "{name}: --accel {accel} differs from the plain loop ({:?}, {} engine)",
                    base.method,
                    base.engine
                );
            }
        }
    }
}

#[test]
fn every_object_a_primary_ray_hits_is_in_its_tiles_mask() {
    // The tile masks promise to keep every object a tile's primary rays can hit,
    // false hits of the rounding included: the textbook quadratic in float32
    // reports hits far outside a small, far sphere's outline (tiny-far,
    // far-sphere), and the mask's margin must hold them too. Checked against the
    // book engine's own first hits, without the masks, in both precisions and
    // methods; and with four samples a pixel, jittered to the pixel's edges, the
    // first hit of each sample, traced here (a record holds its centre ray's).
    // (The margin's 256 unit roundoffs of the squared distance are room to spare:
    // one already holds the false hits here. What this holds is that the margin
    // is there at all.)
    use raystep::fast::masks::TileMasks;
    use raystep::render::Tracer;
    fn masks_of<T: raystep::real::Real>(scene: &Scene, settings: &Settings) -> TileMasks {
        let tracer = Tracer::<T>::new(scene, settings);
        TileMasks::new(&tracer.camera, &tracer.objects)
    }
    /// The first sample ray (of `settings.spp` a pixel, jittered as the render
    /// jitters them) whose first hit is outside its tile's mask, and how many
    /// samples hit something. (A record's `object` is its pixel's centre ray's,
    /// so the samples are traced here.)
    fn sample_outside_mask<T: raystep::real::Real>(
        scene: &Scene,
        settings: &Settings,
    ) -> (Option<String>, usize) {
        let tracer = Tracer::<T>::new(scene, settings);
        let masks = TileMasks::new(&tracer.camera, &tracer.objects);
        let mut hits = 0;
        for row in 0..scene.height {
            for col in 0..scene.width {
                for sample in 0..settings.spp {
                    let (y, x) = raystep::samples::stratified(row, col, sample, settings.spp);
                    let ray = tracer.camera.ray_through::<T>(y, x);
                    let Some(hit) = tracer.nearest_hit(&ray) else {
                        continue;
                    };
                    hits += 1;
                    if masks.mask(row, col) & (1 << hit.object) == 0 {
                        let at = format!("pixel (row {row}, col {col}), sample {sample}");
                        return (Some(format!("{at} hits object {}", hit.object)), hits);
                    }
                }
            }
        }
        (None, hits)
    }
    // tiny-far's sphere fills its picture; on a screen 30 times as wide and high
    // it is a dot of a few pixels, and float32's false hits fall on every tile.
    let mut list = scenes();
    let wide_name = "tiny-far on a wide screen";
    let mut wide = load("scenes/stress/tiny-far.toml", 96, 64);
    let s = wide.screen.as_mut().unwrap();
    let (x, y) = ((s.left + s.right) / 2.0, (s.top + s.bottom) / 2.0);
    let (w, h) = (15.0 * (s.right - s.left), 15.0 * (s.bottom - s.top));
    (s.left, s.right, s.top, s.bottom) = (x - w, x + w, y - h, y + h);
    list.push((wide_name.into(), wide));
    // Pixels of it that float32's textbook quadratic hits and float64's stable
    // test misses: false hits, outside the outline.
    let mut outside_outline = 0;
    let mut sample_hits = 0;
    for (name, scene) in list {
        let mut exact_misses = Vec::new();
        for precision in [Precision::F64, Precision::F32] {
            for method in [Method::Stable, Method::Naive] {
                for spp in [1, 4] {
                    let settings = Settings {
                        precision,
                        method,
                        spp,
                        accel: Accel::Off,
                        ..Settings::from(Stages::ALL)
                    };
                    let masks = match precision {
                        Precision::F64 => masks_of::<f64>(&scene, &settings),
                        Precision::F32 => masks_of::<f32>(&scene, &settings),
                    };
                    if spp > 1 {
                        let (outside, hits) = match precision {
                            Precision::F64 => sample_outside_mask::<f64>(&scene, &settings),
                            Precision::F32 => sample_outside_mask::<f32>(&scene, &settings),
                        };
                        if let Some(outside) = outside {
                            panic!("{name}, {precision:?}, {method:?}, spp {spp}: {outside} outside its tile's mask");
                        }
                        sample_hits += hits;
                    }
                    let frame = render(&scene, &settings, &|_| {});
                    for (i, p) in frame.pixels.iter().enumerate() {
                        if p.object == raystep::aov::NO_OBJECT {
                            continue;
                        }
                        let (row, col) = (i as u32 / frame.width, i as u32 % frame.width);
                        assert!(
                            masks.mask(row, col) & (1 << p.object) != 0,
                            "{name}, {precision:?}, {method:?}, spp {spp}: pixel (row {row}, col {col}) hits object {} outside its tile's mask",
                            p.object
                        );
                    }
                    let misses = frame
                        .pixels
                        .iter()
                        .map(|p| p.object == raystep::aov::NO_OBJECT);
                    if (precision, method, spp) == (Precision::F64, Method::Stable, 1) {
                        exact_misses = misses.collect();
                    } else if (precision, method, spp) == (Precision::F32, Method::Naive, 1)
                        && name == wide_name
                    {
                        outside_outline += misses
                            .zip(&exact_misses)
                            .filter(|&(m, &exact)| !m && exact)
                            .count();
                    }
                }
            }
        }
    }
    assert!(
        outside_outline > 96 * 64 / 4,
        "{outside_outline} false hits in {wide_name}"
    );
    assert!(sample_hits > 10_000, "{sample_hits} samples hit something");
}

/// Every bit of every record ([`common::record_bits`]).
fn bits(frame: &Frame) -> Vec<[u32; 13]> {
    frame.pixels.iter().map(common::record_bits).collect()
}

/// The settings the fast engine must agree with the book engine under: every
/// stage alone and in turn, the tutorial's rules, both precisions, both methods,
/// both offsets (and none at all), both viewers, samples, early stop off, the
/// plain loop and the BVH.
fn packet_settings() -> Vec<(String, Settings)> {
    use raystep::shade::blinn_phong::Viewer;
    use raystep::shade::shadow::Offset;
    use raystep::stages::Stage;
    let all = Settings::from(Stages::ALL);
    let mut list: Vec<(String, Settings)> = Stage::ALL
        .into_iter()
        .map(|s| (format!("up to {s:?}"), Settings::from(Stages::up_to(s))))
        .collect();
    for without in [Stage::Shadow, Stage::BlinnPhong] {
        let stages = Stages::select(Stage::Plane, &[without]).unwrap();
        list.push((format!("without {without:?}"), Settings::from(stages)));
    }
    let f32 = Settings {
        precision: Precision::F32,
        ..all
    };
    list.extend([
        ("tutorial".into(), Settings::tutorial(Stages::ALL)),
        ("f32".into(), f32),
        (
            "f32 tutorial".into(),
            Settings {
                precision: Precision::F32,
                ..Settings::tutorial(Stages::ALL)
            },
        ),
        (
            "f32 fixed:0".into(),
            Settings {
                offset: Offset::Fixed(0.0),
                ..f32
            },
        ),
        (
            "naive auto".into(),
            Settings {
                method: Method::Naive,
                ..all
            },
        ),
        (
            "viewer ray-origin".into(),
            Settings {
                viewer: Viewer::RayOrigin,
                ..all
            },
        ),
        ("spp 4".into(), Settings { spp: 4, ..all }),
        (
            "early stop off".into(),
            Settings {
                early_stop: false,
                ..all
            },
        ),
        (
            "accel off".into(),
            Settings {
                accel: Accel::Off,
                ..all
            },
        ),
        (
            "accel bvh".into(),
            Settings {
                accel: Accel::Bvh,
                ..all
            },
        ),
    ]);
    list
}

/// What a reader who has just changed the book's code is told when the fast
/// engine no longer agrees with it.
const EDITED_THE_BOOK: &str = "\
The fast engine (src/fast/) computes the book's formulas four rays
at a time and must give the book engine's bits. If you have just changed the book's
code (src/render.rs, src/sphere.rs, src/shade/...), this is expected: your change is
in every default render (raystep render, stages, explain and the figures use the
book engine); only --engine fast, bench and chart still compute the old formula.
Render with --engine book (the default) to see your change.";

#[test]
fn the_fast_engine_gives_the_book_engines_bits_on_every_scene() {
    // How many of the fast renders ran in packets, and which fell back.
    let (mut runs, mut fell_back) = (0, Vec::new());
    for (name, mut scene) in scenes() {
        // Odd sizes, so that the last packet of a row is a partial one.
        (scene.width, scene.height) = (61, 37);
        for (what, settings) in packet_settings() {
            let one = |engine, avx| {
                render(
                    &scene,
                    &Settings {
                        engine,
                        avx,
                        ..settings
                    },
                    &|_| {},
                )
            };
            let book = one(Engine::Book, false);
            // Counted inside `trace`, where the primary rays are counted before it
            // (at the `rays` stage no path is traced: the colour is the direction).
            let paths = if settings.stages.intersection {
                book.rays.primary
            } else {
                0
            };
            assert_eq!(
                book.rays.paths, paths,
                "{name}, {what}: the book engine follows every path"
            );
            // The packet tracer's plain x86-64 (SSE2) build, and its AVX build where
            // the processor has AVX (elsewhere the plain one again).
            for (build, fast) in [
                ("sse2", one(Engine::Fast, false)),
                ("avx", one(Engine::Fast, true)),
            ] {
                runs += 1;
                if fast.packets == Packets::Off {
                    fell_back.push(format!("{name}, {what}, {build}"));
                } else {
                    assert_eq!(
                        fast.rays.paths, 0,
                        "{name}, {what}: packets follow no book path"
                    );
                    // The build asked for, where the processor has it.
                    let avx = build == "avx" && has_avx();
                    let expected = if avx { Packets::Avx } else { Packets::Baseline };
                    assert_eq!(fast.packets, expected, "{name}, {what}, {build}");
                }
                let rays = |r: Rays| Rays { paths: 0, ..r };
                assert_eq!(
                    rays(book.rays), rays(fast.rays),
                    "{name}, {what}, fast engine ({build} build): ray counts differ from the book engine's\n{EDITED_THE_BOOK}"
                );
                let (a, b) = (bits(&book), bits(&fast));
                if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
                    panic!(
                        "{name}, {what}, fast engine ({build} build): pixel (row {}, col {}) differs: {:?} against the book engine's {:?}\n{EDITED_THE_BOOK}",
                        i / 61,
                        i % 61,
                        fast.pixels[i],
                        book.pixels[i]
                    );
                }
            }
        }
    }
    // Every scene and setting here is one the packets take: a fast render
    // left to the book's rows would hold the book engine to itself.
    assert!(runs > 1000, "{runs} fast renders");
    assert!(
        fell_back.is_empty(),
        "left to the book's rows: {fell_back:#?}"
    );
}

#[test]
fn the_bvh_changes_no_pixel_in_float32_with_the_stable_method_either() {
    let mut scene = raystep::tools::generate::scene(200, 9);
    (scene.width, scene.height) = (160, 90);
    let base = Settings {
        precision: Precision::F32,
        method: Method::Stable,
        ..Settings::from(Stages::ALL)
    };
    let off = render(
        &scene,
        &Settings {
            accel: Accel::Off,
            ..base
        },
        &|_| {},
    );
    let bvh = render(
        &scene,
        &Settings {
            accel: Accel::Bvh,
            ..base
        },
        &|_| {},
    );
    assert!(off.pixels == bvh.pixels);
}

#[test]
fn the_yardstick_draws_exactly_the_tutorial_settings_image() {
    for (w, h) in [(300, 200), (97, 61)] {
        let scene = common::seed(w, h);
        let ours = render(&scene, &Settings::tutorial(Stages::ALL), &|_| {});
        let port = Yardstick::new(&scene)
            .expect("the seed scene has only spheres")
            .render();
        assert_eq!(port.len(), ours.pixels.len());
        for (i, (a, b)) in port.iter().zip(&ours.pixels).enumerate() {
            assert_eq!(a.as_vec3().to_array(), b.colour, "pixel {i} at {w} × {h}");
        }
    }
}

#[test]
fn the_yardstick_counts_the_rays_the_tutorials_program_casts() {
    // The same paths as the book's render under --tutorial, counted pixel by pixel.
    for (w, h) in [(300, 200), (97, 61)] {
        let scene = common::seed(w, h);
        let ours = render(&scene, &Settings::tutorial(Stages::ALL), &|_| {});
        let port = Yardstick::new(&scene).expect("the seed scene has only spheres");
        let (mut image, mut rays) = (Vec::new(), Vec::new());
        let total = port.render_into(&mut image, &mut rays);
        assert_eq!(total, ours.rays.total(), "{w} × {h}");
        for (i, (r, p)) in rays.iter().zip(&ours.pixels).enumerate() {
            assert_eq!(*r, p.rays, "pixel {i} at {w} × {h}");
        }
    }
    // TUTORIAL.md's 60,000 + 43,331 + 36,140 rays at 300 × 200.
    let port = Yardstick::new(&common::seed(300, 200)).unwrap();
    assert_eq!(port.render_into(&mut Vec::new(), &mut Vec::new()), 139_471);
}

/// The tutorial's rule for a hit: both roots of the quadratic positive. From
/// inside a sphere one root is negative, so the tutorial's program sees nothing of
/// a sphere around the camera: every pixel that misses the small sphere inside is
/// black and cast its primary ray only, and the whole picture and every count are
/// the book engine's under `--tutorial`. (A scene file cannot put the camera
/// inside a sphere; the library's `Scene` can, and the port keeps the rule.)
#[test]
fn the_yardstick_sees_nothing_of_a_sphere_around_the_camera() {
    let mut scene = raystep::io::scene_file::parse(
        "[image]\nwidth = 40\nheight = 30\n[camera]\nposition = [0, 0, 9]\n\
         [light]\nposition = [0, 9, 9]\n[render]\nmax_depth = 3\n\
         [[sphere]]\ncenter = [0, 0, 0]\nradius = 5\n\
         ambient = [0.1, 0.1, 0.1]\ndiffuse = [0.6, 0.6, 0.6]\n\
         [[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\n\
         ambient = [0.1, 0, 0]\ndiffuse = [0.7, 0, 0]\n",
        "around.toml",
    )
    .unwrap();
    scene.camera = glam::DVec3::new(0.0, 0.0, 1.0);
    scene.light.position = glam::DVec3::new(0.0, 1.0, 1.0);
    let port = Yardstick::new(&scene).expect("only spheres");
    let (mut image, mut rays) = (Vec::new(), Vec::new());
    let total = port.render_into(&mut image, &mut rays);
    let ours = render(&scene, &Settings::tutorial(Stages::ALL), &|_| {});
    let mut missed = 0;
    for (i, ((colour, r), p)) in image.iter().zip(&rays).zip(&ours.pixels).enumerate() {
        assert_eq!(colour.as_vec3().to_array(), p.colour, "pixel {i}");
        assert_eq!(*r, p.rays, "pixel {i}");
        if p.object == raystep::aov::NO_OBJECT {
            missed += 1;
            assert_eq!(
                *colour,
                glam::DVec3::ZERO,
                "pixel {i} sees the sphere around it"
            );
            assert_eq!(*r, 1, "pixel {i}");
        }
    }
    assert!(missed > 0 && missed < 40 * 30, "{missed} pixels miss");
    assert_eq!(total, ours.rays.total());
}

/// `raystep bench` renders every measurement once to warm up, then `runs`
/// times: its progress hears of `runs + 1` runs, and the report says `runs`.
#[test]
fn bench_runs_one_warm_up_then_the_runs_asked_for() {
    use raystep::tools::bench::{bench, Options};
    let scene = common::seed(8, 6);
    let settings = Settings::from(Stages::ALL);
    for runs in [1, 2, 4] {
        let heard = Cell::new(0);
        let options = Options {
            runs,
            threads: 2,
            yardstick: true,
        };
        let report = bench(&scene, &settings, options, &|n| heard.set(heard.get() + n)).unwrap();
        assert_eq!(heard.get(), runs as u64 + 1, "{runs} runs");
        assert_eq!(report.runs, runs);
    }
}

#[test]
fn the_yardstick_refuses_a_true_plane() {
    assert!(Yardstick::new(&load("scenes/true-plane.toml", 10, 10)).is_none());
}

#[test]
fn ray_counts_are_the_tutorials_own() {
    // TUTORIAL.md: at 300 × 200 the tutorial's program casts 60,000 primary,
    // 43,331 shadow and 36,140 reflection rays.
    let frame = render(
        &common::seed(300, 200),
        &Settings::tutorial(Stages::ALL),
        &|_| {},
    );
    assert_eq!(
        frame.rays,
        Rays {
            primary: 60_000,
            shadow: 43_331,
            reflection: 36_140,
            paths: 60_000,
        }
    );
    // No shadow rays without the shadow stage; no reflection rays without reflection.
    let no_shadow = Stages::select(
        raystep::stages::Stage::Plane,
        &[raystep::stages::Stage::Shadow],
    )
    .unwrap();
    let frame = render(
        &common::seed(300, 200),
        &Settings::tutorial(no_shadow),
        &|_| {},
    );
    assert_eq!(frame.rays.shadow, 0);
    let up_to_shading = Stages::up_to(raystep::stages::Stage::BlinnPhong);
    let frame = render(
        &common::seed(300, 200),
        &Settings::tutorial(up_to_shading),
        &|_| {},
    );
    assert_eq!(frame.rays.reflection, 0);
    assert_eq!(frame.rays.primary, 60_000);
}

#[test]
fn samples_are_stratified_inside_their_pixel_and_the_same_every_time() {
    // SplitMix64's published first output from a state of 0 (the reference
    // implementation adds the constant, then mixes).
    assert_eq!(raystep::samples::splitmix64(0), 0xe220_a839_7b1d_cdaf);
    // Where each sample lies inside its cell, as a fraction of the cell.
    let mut within = Vec::new();
    for spp in [4u32, 9, 16] {
        let n = spp.isqrt();
        let pixels = (0..40u32).flat_map(|row| (0..25u32).map(move |col| (row * 27, col * 80)));
        for (row, col) in pixels.chain([(1079, 1919)]) {
            for s in 0..spp {
                let (y, x) = stratified(row, col, s, spp);
                // Inside cell (s / n, s % n) of the pixel's n × n grid.
                let in_y = (y - f64::from(row) + 0.5) * f64::from(n);
                let in_x = (x - f64::from(col) + 0.5) * f64::from(n);
                assert_eq!(
                    (in_y.floor() as u32, in_x.floor() as u32),
                    (s / n, s % n),
                    "spp {spp} sample {s}"
                );
                within.extend([in_y.fract(), in_x.fract()]);
            }
        }
    }
    // Jittered, not the cells' corners or centres: spread over the whole cell,
    // half of it on average (58,058 numbers: a mean of uniform ones is 0.5 within
    // 0.0012, one standard deviation).
    let (least, most) = within
        .iter()
        .fold((1.0f64, 0.0f64), |(l, m), &v| (l.min(v), m.max(v)));
    let mean = within.iter().sum::<f64>() / within.len() as f64;
    assert!(least < 0.01 && most > 0.99, "{least} to {most}");
    assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
}

#[test]
fn more_samples_smooth_edges_keep_flat_areas_and_keep_the_buffers() {
    let scene = common::seed(120, 80);
    let one = render(&scene, &Settings::from(Stages::ALL), &|_| {});
    let settings = Settings {
        spp: 16,
        ..Settings::from(Stages::ALL)
    };
    let many = render(&scene, &settings, &|_| {});
    // The buffers come from the centre ray, whatever the samples.
    for (a, b) in one.pixels.iter().zip(&many.pixels) {
        assert_eq!((a.depth, a.normal, a.shadow), (b.depth, b.normal, b.shadow));
    }
    // 16 samples and the centre ray per pixel.
    assert_eq!(many.rays.primary, 17 * 120 * 80);
    // Sky far from any edge: the same colour (black).
    assert_eq!(many.at(0, 0).colour, one.at(0, 0).colour);
    // Lit, smooth areas: where a pixel's eight neighbours are within an 8-bit
    // step of it, the samples, all inside the pixel, average to about its colour.
    let step = 1.0 / 255.0;
    let near = |a: [f32; 3], b: [f32; 3], by: f32| (0..3).all(|k| (a[k] - b[k]).abs() <= by);
    let mut flat = 0;
    for row in 1..79 {
        for col in 1..119 {
            let c = one.at(row, col).colour;
            let smooth = (row - 1..=row + 1)
                .all(|r| (col - 1..=col + 1).all(|k| near(one.at(r, k).colour, c, step)));
            if smooth && c.iter().any(|&v| v > 0.05) {
                flat += 1;
                let m = many.at(row, col).colour;
                assert!(near(m, c, step), "({row}, {col}): {m:?} against {c:?}");
            }
        }
    }
    assert!(flat > 1000, "{flat} smooth lit pixels");
    // At least some edge pixels now hold a mix.
    let changed = one
        .pixels
        .iter()
        .zip(&many.pixels)
        .filter(|(a, b)| a.colour != b.colour)
        .count();
    assert!(changed > 100, "{changed}");
    // The same on one thread and several.
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert!(single.install(|| render(&scene, &settings, &|_| {})).pixels == many.pixels);
}

#[test]
fn early_stop_moves_no_channel_more_than_one_8_bit_level_and_saves_rays() {
    // A corridor of two mirrors, floor and ceiling: every ray that is not level
    // bounces between them until max_depth. The light's diffuse colour is tiny, so
    // a bound built on kd·ld would be too small once Blinn-Phong is off.
    let mut scene = common::scene(
        "[image]\nwidth = 120\nheight = 80\n[camera]\nposition = [0, 0, 1]\n\
         [light]\nposition = [0, 0, -5]\ndiffuse = [0.0001, 0.0001, 0.0001]\n\
         [[plane]]\npoint = [0, -1, 0]\nnormal = [0, 1, 0]\nreflection = 0.7\n\
         ambient = [0, 0, 0]\ndiffuse = [0.2, 0.05, 0.05]\nspecular = [0, 0, 0]\n\
         [[plane]]\npoint = [0, 1, 0]\nnormal = [0, -1, 0]\nreflection = 0.7\n\
         ambient = [0, 0, 0]\ndiffuse = [0.05, 0.05, 0.2]\nspecular = [0, 0, 0]\n",
    );
    scene.max_depth = 48;
    // Without shadows, so that paths are not cut short at a shadowed point.
    let stages = Stages::select(
        raystep::stages::Stage::Plane,
        &[raystep::stages::Stage::Shadow],
    )
    .unwrap();
    let base = Settings::from(stages);
    let on = render(
        &scene,
        &Settings {
            early_stop: true,
            ..base
        },
        &|_| {},
    );
    let off = render(
        &scene,
        &Settings {
            early_stop: false,
            ..base
        },
        &|_| {},
    );
    assert!(
        on.rays.reflection < off.rays.reflection,
        "{:?} {:?}",
        on.rays,
        off.rays
    );
    let level = |c: f32| (c * 255.0).round() as i32;
    for (a, b) in on.pixels.iter().zip(&off.pixels) {
        for c in 0..3 {
            assert!((level(a.colour[c]) - level(b.colour[c])).abs() <= 1);
            // Half a step, before rounding: the bound it is built on.
            assert!((a.colour[c] - b.colour[c]).abs() <= 0.5 / 255.0 + 1e-7);
        }
    }
}

#[test]
fn the_pixel_loop_allocates_nothing() {
    let mut many = raystep::tools::generate::scene(100, 3);
    (many.width, many.height) = (64, 36);
    for (scene, settings) in [
        (common::seed(64, 36), Settings::from(Stages::ALL)),
        (common::seed(64, 36), Settings::tutorial(Stages::ALL)),
        (
            common::seed(64, 36),
            Settings {
                spp: 4,
                ..Settings::from(Stages::ALL)
            },
        ),
        (many, Settings::from(Stages::ALL)),
    ] {
        let fast = Fast::<f64>::new(&scene, &settings);
        let mut line = vec![PixelRecord::new(Default::default(), None, 0, 0); scene.width as usize];
        COUNTING.with(|c| c.set(true));
        let (mut sum, mut packed) = (0.0, 0.0);
        for row in 0..scene.height {
            // The book's row loop, and the packet loop where the scene has one.
            book_row(&fast.book, settings.spp, row, &mut line);
            sum += line.iter().map(|p| p.colour[0]).sum::<f32>();
            if fast.packets {
                fast.packet_row(row, &mut line);
                packed += line.iter().map(|p| p.colour[0]).sum::<f32>();
            }
        }
        COUNTING.with(|c| c.set(false));
        assert!(sum > 0.0);
        assert!(!fast.packets || packed > 0.0);
        assert_eq!(
            ALLOCATIONS.with(Cell::get),
            0,
            "allocations in the pixel loop"
        );
    }
}

/// README.md and `--accel`'s help: `--accel auto` builds a BVH "from 24 spheres
/// on": a scene of 24 spheres (and its floor) gets one, a scene of 23 none.
#[test]
fn accel_auto_builds_the_bvh_from_24_spheres_on() {
    use raystep::render::Tracer;
    let settings = Settings::from(Stages::ALL);
    assert_eq!(settings.accel, Accel::Auto);
    for (count, tree) in [(23, false), (24, true)] {
        let scene = raystep::io::scene_file::parse(
            &raystep::tools::generate::spheres_toml(count, 1),
            "generated.toml",
        )
        .unwrap();
        assert_eq!(
            Tracer::<f64>::new(&scene, &settings).bvh.is_some(),
            tree,
            "{count}"
        );
        assert_eq!(
            Tracer::<f32>::new(&scene, &settings).bvh.is_some(),
            tree,
            "{count}"
        );
    }
}

#[test]
fn a_packets_records_are_stored_as_copy_from_slice_would_store_them() {
    // `store_packet` writes a whole packet on 16 bytes with non-temporal stores
    // and any other with an ordinary copy: either way the bytes of
    // `copy_from_slice`, and nothing outside the packet. A record is 52 bytes,
    // 4 more than a multiple of 16, so of four neighbouring places one starts on
    // 16 bytes and three do not; every place from 0 to 7 is tried, whole and as
    // the short packet at a row's end.
    use raystep::fast::lanes::WIDTH;
    use raystep::fast::packet::{finish_stores, store_packet};
    let record = |k: usize| {
        let v = k as f32 + 0.5;
        let mut r = PixelRecord::missed([v, -v, v * 3.0], k as u64, 2 * k as u64 + 1);
        r.set_hit(v, [0.25, -v, 1.0], k.is_multiple_of(2), k, v / 7.0, v * v);
        r
    };
    let records: [PixelRecord; WIDTH] = std::array::from_fn(|i| record(100 + i));
    let (mut aligned, mut misaligned) = (0, 0);
    for start in 0..8 {
        for n in 1..=WIDTH {
            let mut ours: Vec<PixelRecord> = (0..16).map(record).collect();
            let mut copied = ours.clone();
            store_packet(&mut ours[start..start + n], &records);
            finish_stores();
            copied[start..start + n].copy_from_slice(&records[..n]);
            let ours_bits: Vec<_> = ours.iter().map(common::record_bits).collect();
            let copied_bits: Vec<_> = copied.iter().map(common::record_bits).collect();
            assert_eq!(ours_bits, copied_bits, "{n} records at {start}");
            if n == WIDTH {
                match (ours[start..].as_ptr() as usize).is_multiple_of(16) {
                    true => aligned += 1,
                    false => misaligned += 1,
                }
            }
        }
    }
    // Both ways of storing a whole packet were taken.
    assert!(
        aligned >= 1 && misaligned >= 1,
        "{aligned} on 16 bytes, {misaligned} not"
    );
}
