//! The figure-1 scene against the image the tutorial's own program made.

mod common;

use raystep::render::Settings;
use raystep::stages::{Engine, Stages};

/// raystep computes in float64 like the tutorial's program and stores float32, as
/// the PFM does. Measured on this machine: every float32 value is identical (a
/// tolerance of 0 passes). The tolerance leaves room for another libm's `pow`
/// and `sqrt` rounding, which can move a float64 result by an ulp or so, and for
/// the `N·H ≥ 0` clamp (at most 2.2e-12 on this scene, chapter 8); it is still 1/4000 of an
/// 8-bit step.
const TOLERANCE: f32 = 1e-6;

#[test]
fn every_stage_on_reproduces_the_tutorials_figure_1_with_the_book_engine() {
    reproduces_figure_1(Engine::Book);
}

#[test]
fn every_stage_on_reproduces_the_tutorials_figure_1_with_the_fast_engine() {
    reproduces_figure_1(Engine::Fast);
}

fn reproduces_figure_1(engine: Engine) {
    let (w, h, reference) = common::read_pfm(include_bytes!("data/seed-300x200.pfm"));
    assert_eq!((w, h), (300, 200));
    let settings = Settings {
        engine,
        ..Settings::tutorial(Stages::ALL)
    };
    let frame = raystep::engine::render(&common::seed(300, 200), &settings, &|_| {});
    assert_eq!(frame.engine, engine);
    assert_eq!(frame.pixels.len(), reference.len());
    let mut worst = (0.0f32, 0usize);
    for (i, (ours, theirs)) in frame.pixels.iter().zip(&reference).enumerate() {
        for (a, b) in ours.colour.iter().zip(theirs) {
            let diff = (a - b).abs();
            if diff > worst.0 {
                worst = (diff, i);
            }
        }
    }
    let (row, col) = (worst.1 / w, worst.1 % w);
    assert!(
        worst.0 <= TOLERANCE,
        "{engine} engine: pixel (row {row}, col {col}) differs by {}: ours {:?}, reference {:?}",
        worst.0,
        frame.pixels[worst.1].colour,
        reference[worst.1]
    );
    // The reference is not trivially matched: most pixels are lit, colourful ones.
    let coloured = reference
        .iter()
        .filter(|p| p.iter().any(|&c| c > 0.05))
        .count();
    assert!(coloured > w * h / 2, "{coloured}");
}
