//! The two engines behind one call: the book's tracer ([`crate::render`], the
//! default) or the fast one ([`crate::fast`]), as `--engine` asks. Both give the
//! same bits; this is the one place that chooses.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::aov::Frame;
use crate::render::{Progress, Settings};
use crate::scene::Scene;
use crate::stages::Engine;

/// Render `scene` under `settings` with the engine they name, telling `progress`
/// of each row finished (from any thread).
pub fn render(scene: &Scene, settings: &Settings, progress: &dyn Progress) -> Frame {
    let mut frame = Frame::blank(scene.camera(), settings.precision);
    render_into(scene, settings, &mut frame, progress);
    frame
}

/// [`render`] into a frame of the scene's size that is already allocated (as
/// `raystep bench` does, to time the render alone).
pub fn render_into(scene: &Scene, settings: &Settings, frame: &mut Frame, progress: &dyn Progress) {
    match settings.engine {
        Engine::Book => crate::render::render_into(scene, settings, frame, progress),
        Engine::Fast => crate::fast::render_into(scene, settings, frame, progress),
    }
}

/// [`render`], unless `cancel` is set before it ends: then no new row is
/// started and the answer is `None` (the unfinished frame is thrown away).
/// `raystep serve` sets it when a newer request supersedes the render.
/// `row_done` is told of each row finished (from any thread), as a
/// [`Progress`] is.
pub fn render_cancellable(
    scene: &Scene,
    settings: &Settings,
    cancel: &AtomicBool,
    row_done: &(dyn Fn() + Sync),
) -> Option<Frame> {
    /// Rows are told to the caller; the flag is asked before each one.
    struct Unless<'a>(&'a AtomicBool, &'a (dyn Fn() + Sync));
    impl Progress for Unless<'_> {
        fn row_done(&self) {
            (self.1)()
        }
        fn cancelled(&self) -> bool {
            self.0.load(Ordering::Relaxed)
        }
    }
    let frame = render(scene, settings, &Unless(cancel, row_done));
    (!cancel.load(Ordering::SeqCst)).then_some(frame)
}
