//! Ctrl-C (and `kill`): a render stops between rows and nothing is written, so the
//! files of the render before it stay as they were.
//!
//! The first signal only raises a flag: the pixel loop stops taking new rows, and
//! the files of the interrupted render are never renamed into place (see
//! [`crate::io::output::Pending`]). A second signal ends the process at once, for the
//! case where something does not stop; the temporary files it leaves are removed
//! by the next run that writes to the same folder.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The exit code of a process ended by SIGINT, as shells report it (128 + 2).
pub const EXIT_CODE: u8 = 130;

/// Catch SIGINT, SIGTERM and SIGHUP for the rest of the process (the binary calls
/// this once; a library user who does not keeps the default behaviour).
pub fn install() {
    // Fails only if a handler is already set: then that one stays.
    let _ = ctrlc::set_handler(|| {
        if REQUESTED.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(EXIT_CODE));
        }
    });
}

/// Whether an interrupt has been asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}
