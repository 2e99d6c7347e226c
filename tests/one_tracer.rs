//! The code the book shows is the code that renders: a default render follows
//! every pixel's path through the book's `Tracer::pixel` and `Tracer::trace`
//! (src/render.rs), and only `--engine fast` leaves them to the packet tracer.
//! The paths are counted inside `trace` (`Rays::paths`, at a path's first
//! segment). (`tests/speed.rs` holds the two engines to the same bits.)

mod common;

use raystep::aov::Packets;
use raystep::engine::render;
use raystep::render::Settings;
use raystep::stages::{Engine, Stage, Stages};

#[test]
fn a_default_render_follows_every_path_through_the_books_trace() {
    let scene = common::seed(48, 32);
    let pixels = 48 * 32;
    for stage in Stage::ALL {
        for settings in [
            Settings::from(Stages::up_to(stage)),
            Settings::tutorial(Stages::up_to(stage)),
        ] {
            assert_eq!(settings.engine, Engine::Book, "the default engine");
            let frame = render(&scene, &settings, &|_| {});
            assert_eq!(frame.engine, Engine::Book);
            assert_eq!(frame.packets, Packets::Off);
            assert_eq!(
                frame.rays.primary, pixels,
                "{stage}: a primary ray per pixel"
            );
            // At the `rays` stage `pixel` colours the direction and traces nothing.
            let paths = if stage == Stage::Rays { 0 } else { pixels };
            assert_eq!(frame.rays.paths, paths, "{stage}: one book path per pixel");
        }
    }
    // Samples are traced by the book too: the centre ray and four samples.
    let spp = Settings {
        spp: 4,
        ..Settings::from(Stages::ALL)
    };
    assert_eq!(render(&scene, &spp, &|_| {}).rays.paths, 5 * pixels);
}

#[test]
fn the_fast_engine_leaves_the_books_trace_except_where_it_falls_back() {
    let settings = Settings {
        engine: Engine::Fast,
        ..Settings::from(Stages::ALL)
    };
    let frame = render(&common::seed(48, 32), &settings, &|_| {});
    assert_eq!(frame.engine, Engine::Fast);
    assert_ne!(frame.packets, Packets::Off);
    assert_eq!(frame.rays.paths, 0, "the packets trace every pixel");
    // More objects than the packets' masks hold, and no BVH: the book's loop.
    let mut many = raystep::tools::generate::scene(80, 2);
    (many.width, many.height) = (24, 16);
    let plain = Settings {
        accel: raystep::accel::Accel::Off,
        ..settings
    };
    let frame = render(&many, &plain, &|_| {});
    assert_eq!(frame.packets, Packets::Off);
    assert_eq!(
        frame.rays.paths,
        24 * 16,
        "the fallback is the book's engine"
    );
}
