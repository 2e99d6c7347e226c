//! What each method costs: `cargo bench --bench methods`.
//!
//! Renders of figure 1 (320 × 240, every stage) with the book engine for six of
//! the eight combinations of precision × intersection method × offset (the
//! textbook test with the `auto` offset is left out: that offset was derived for
//! the stable test), the book engine against the fast one, the fake floor against
//! a true plane (book engine), the ray-sphere intersection alone, and the BVH's
//! build and search, one ray at a time.

use divan::Bencher;
use raystep::ray::Ray;
use raystep::real::{Precision, Real, Vector};
use raystep::render::{render, Settings};
use raystep::shade::shadow::Offset;
use raystep::sphere::{Method, Sphere};
use raystep::stages::{Engine, Stages};
use raystep::Vec3;

fn main() {
    divan::main();
}

fn seed() -> raystep::scene::Scene {
    let mut scene = raystep::io::scene_file::seed();
    (scene.width, scene.height) = (320, 240);
    scene
}

const CONFIGS: [(&str, Precision, Method, Offset); 6] = [
    (
        "f64 naive fixed (tutorial)",
        Precision::F64,
        Method::Naive,
        Offset::TUTORIAL,
    ),
    (
        "f64 stable fixed",
        Precision::F64,
        Method::Stable,
        Offset::TUTORIAL,
    ),
    (
        "f64 stable auto (default)",
        Precision::F64,
        Method::Stable,
        Offset::Auto,
    ),
    (
        "f32 naive fixed",
        Precision::F32,
        Method::Naive,
        Offset::TUTORIAL,
    ),
    (
        "f32 stable fixed",
        Precision::F32,
        Method::Stable,
        Offset::TUTORIAL,
    ),
    (
        "f32 stable auto",
        Precision::F32,
        Method::Stable,
        Offset::Auto,
    ),
];

/// Figure 1 with the book engine, one of [`CONFIGS`] (divan prints its name).
#[divan::bench(args = CONFIGS.map(|c| c.0), sample_count = 60)]
fn figure_1(bencher: Bencher, name: &str) {
    let (_, precision, method, offset) = CONFIGS
        .into_iter()
        .find(|c| c.0 == name)
        .expect("a name from CONFIGS");
    let scene = seed();
    let settings = Settings {
        precision,
        method,
        offset,
        ..Settings::from(Stages::ALL)
    };
    bencher.bench(|| render(&scene, &settings, &|_| {}));
}

/// Figure 1 with the defaults: the book's engine, one ray at a time, against the
/// fast one, four at once.
#[divan::bench(args = ["book", "fast"], sample_count = 60)]
fn engines(bencher: Bencher, how: &str) {
    let scene = seed();
    let settings = Settings {
        engine: match how {
            "fast" => Engine::Fast,
            _ => Engine::Book,
        },
        ..Settings::from(Stages::ALL)
    };
    bencher.bench(|| raystep::engine::render(&scene, &settings, &|_| {}));
}

#[divan::bench(args = ["fake", "true"], sample_count = 60)]
fn floor(bencher: Bencher, kind: &str) {
    let scene = match kind {
        "fake" => seed(),
        _ => {
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/true-plane.toml");
            let mut s = raystep::io::scene_file::load(path.as_ref()).unwrap();
            (s.width, s.height) = (320, 240);
            s
        }
    };
    let settings = Settings::from(Stages::ALL);
    bencher.bench(|| render(&scene, &settings, &|_| {}));
}

/// 4,096 rays from the camera towards the red sphere and around it.
fn rays<T: Real>() -> Vec<Ray<T>> {
    (0..4096)
        .map(|i| {
            let (x, y) = ((i % 64) as f64 / 32.0 - 1.0, (i / 64) as f64 / 32.0 - 1.0);
            Ray::towards(
                T::Vec3::of(Vec3::new(0.0, 0.0, 1.0)),
                T::Vec3::of(Vec3::new(x, y, -1.0)),
            )
        })
        .collect()
}

#[divan::bench(types = [f32, f64], args = ["naive", "stable"])]
fn intersect<T: Real>(bencher: Bencher, method: &str) {
    let method = if method == "naive" {
        Method::Naive
    } else {
        Method::Stable
    };
    let sphere = Sphere::<T> {
        center: T::Vec3::of(Vec3::new(-0.2, 0.0, -1.0)),
        radius: T::of(0.7),
    };
    let rays = rays::<T>();
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| {
            rays.iter()
                .filter(|r| sphere.intersect(divan::black_box(r), method).is_some())
                .count()
        });
}

/// Building the BVH over N generated spheres (the target: a million in
/// under a second).
#[divan::bench(args = [1_000, 100_000, 1_000_000], sample_count = 5)]
fn bvh_build(bencher: Bencher, count: usize) {
    let scene = raystep::tools::generate::scene(count, 1);
    let objects: Vec<raystep::scene::Object> = scene.objects_in_play(Stages::ALL);
    bencher.bench(|| raystep::bvh::Bvh::build(&objects));
}

/// The nearest hit of 4,096 primary rays among N generated spheres, one ray at
/// a time: the plain loop against the BVH. Here they cross between 4 and 8
/// spheres; `accel::BVH_FROM` (24) is where they cross four rays at a time, in
/// the fast engine with its tile masks, and is measured with `raystep bench`.
#[divan::bench(args = [4, 8, 12, 16, 32, 1_000])]
fn nearest_hit_list(bencher: Bencher, count: usize) {
    let (objects, rays) = spheres_and_rays(count);
    bencher.bench(|| {
        rays.iter()
            .filter(|r| {
                raystep::scene::nearest_hit(&objects, divan::black_box(r), Method::Stable).is_some()
            })
            .count()
    });
}

/// See [`nearest_hit_list`].
#[divan::bench(args = [4, 8, 12, 16, 32, 1_000, 100_000])]
fn nearest_hit_bvh(bencher: Bencher, count: usize) {
    let (objects, rays) = spheres_and_rays(count);
    let bvh = raystep::bvh::Bvh::build(&objects);
    bencher.bench(|| {
        rays.iter()
            .filter(|r| {
                bvh.nearest_hit(&objects, divan::black_box(r), Method::Stable)
                    .is_some()
            })
            .count()
    });
}

fn spheres_and_rays(count: usize) -> (Vec<raystep::scene::Object>, Vec<Ray<f64>>) {
    let mut scene = raystep::tools::generate::scene(count, 1);
    (scene.width, scene.height) = (64, 64);
    let camera = scene.camera();
    let rays = (0..64 * 64)
        .map(|i| camera.primary_ray::<f64>(i / 64, i % 64))
        .collect();
    (scene.objects_in_play(Stages::ALL), rays)
}
