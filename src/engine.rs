//! The two engines behind one call: the book's tracer ([`crate::render`], the
//! default) or the fast one ([`crate::fast`]), as `--engine` asks. Both give the
//! same bits; this is the one place that chooses.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::aov::Frame;
use crate::render::Settings;
use crate::scene::Scene;
use crate::stages::Engine;

/// Render `scene` under `settings` with the engine they name. `progress(1)` is
/// called, from any thread, each time a row is finished.
pub fn render(scene: &Scene, settings: &Settings, progress: &(dyn Fn(u64) + Sync)) -> Frame {
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    render_into(scene, settings, &mut frame, progress);
    frame
}

/// [`render`] into a frame of the scene's size that is already allocated (as
/// `raystep bench` does, to time the render alone).
pub fn render_into(
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &(dyn Fn(u64) + Sync),
) {
    render_unless(scene, settings, frame, progress, &AtomicBool::new(false));
}

/// [`render`], unless `cancel` is set before it ends: then no new row is
/// started and the answer is `None` (the unfinished frame is thrown away).
/// `raystep serve` sets it when a newer request supersedes the render.
pub fn render_cancellable(
    scene: &Scene,
    settings: &Settings,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Option<Frame> {
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    render_unless(scene, settings, &mut frame, progress, cancel);
    (!cancel.load(Ordering::SeqCst)).then_some(frame)
}

fn render_unless(
    scene: &Scene,
    settings: &Settings,
    frame: &mut Frame,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) {
    match settings.engine {
        Engine::Book => crate::render::render_into(scene, settings, frame, progress, cancel),
        Engine::Fast => crate::fast::render_into(scene, settings, frame, progress, cancel),
    }
}
