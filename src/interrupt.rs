//! Ctrl-C (and `kill`): a command stops within a second, with exit code 130, and
//! nothing is written, so the files of the run before it stay as they were.
//!
//! The first signal raises a flag: the pixel loop stops taking new rows, and the
//! files of the interrupted render are never renamed into place (see
//! [`crate::io::output::Pending`]). Work that does not look at the flag (reading a
//! FIFO that nobody writes, a benchmark's runs, the accuracy measurements) is ended
//! by a watchdog [`GRACE`] later: it waits for any renaming under way to finish
//! ([`files`]), removes the temporary files of this process, says so
//! ([`WATCHDOG_MESSAGE`]) and exits, unless the
//! new files were put in place meanwhile ([`committed`]): the command then ends by
//! itself, with its own exit code. A second
//! signal ends the process at once; the temporary files it leaves are removed by
//! the next run that writes to the same folder.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Set once a set of files has been put in place ([`committed`]): the command's
/// work is then done, and it is left to end by itself with its own exit code.
static COMMITTED: AtomicBool = AtomicBool::new(false);

/// What this process has made and not yet committed or removed, in the order it
/// made them: temporary files, and the folders created for them (`true`). The
/// lock is held while files are renamed into place.
static MADE: Mutex<Vec<(PathBuf, bool)>> = Mutex::new(Vec::new());

/// The exit code of a process ended by SIGINT, as shells report it (128 + 2).
pub const EXIT_CODE: u8 = 130;

/// What the watchdog says on standard error as it ends a command.
pub const WATCHDOG_MESSAGE: &str =
    "interrupted: stopped half a second after the signal, and nothing was written";

/// How long after the first signal the watchdog ends a command that has not
/// ended by itself.
pub const GRACE: Duration = Duration::from_millis(500);

/// Catch SIGINT, SIGTERM and SIGHUP for the rest of the process (the binary calls
/// this once; a library user who does not keeps the default behaviour).
pub fn install() {
    // Fails only if a handler is already set: then that one stays.
    let _ = ctrlc::set_handler(|| {
        if REQUESTED.swap(true, Ordering::SeqCst) {
            std::process::exit(i32::from(EXIT_CODE));
        }
        std::thread::spawn(|| {
            std::thread::sleep(GRACE);
            // Not in the middle of a commit: remove what was made, newest first
            // (a folder is removed only if empty, as the commit would have left it).
            let made = files();
            if COMMITTED.load(Ordering::SeqCst) {
                // The signal came too late: the new files are in place, and the
                // command ends by itself (exit 0) once it has said so. Ending it
                // with 130 here, on a busy machine, would report an interrupted
                // run whose files were all written.
                return;
            }
            for (path, folder) in made.iter().rev() {
                let _ = match folder {
                    true => std::fs::remove_dir(path),
                    false => std::fs::remove_file(path),
                };
            }
            // Said as the command's own errors are (and not lost if standard
            // error is closed: `eprintln!` would panic).
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "error: {WATCHDOG_MESSAGE}");
            std::process::exit(i32::from(EXIT_CODE));
        });
    });
}

/// Whether an interrupt has been asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// What this process has made and not committed (path, and whether it is a
/// folder), locked: while it is held, the watchdog cannot end the process (hold it
/// to rename files into place together).
pub fn files() -> MutexGuard<'static, Vec<(PathBuf, bool)>> {
    MADE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Note that the temporary file (or, with `folder`, the folder) `path` was made,
/// for the watchdog to remove.
pub fn made(path: &Path, folder: bool) {
    files().push((path.to_path_buf(), folder));
}

/// The files of this run were put in place (called under the lock of [`files`]).
pub fn committed() {
    COMMITTED.store(true, Ordering::SeqCst);
}

/// `path` was committed (renamed, or kept) or removed.
pub fn forget(path: &Path) {
    files().retain(|(p, _)| p != path);
}
