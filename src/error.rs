//! Errors a user can cause, each a message that says what is wrong and what would
//! be valid. The command line prints them and exits with [`USER_ERROR`] (130 after
//! an interrupt).

use std::fmt;
use std::path::PathBuf;

/// The exit code for every mistake a user can make (bad scene, flag or folder).
pub const USER_ERROR: i32 = 2;

/// Something raystep was asked to do and cannot.
#[derive(Debug)]
pub enum Error {
    /// A scene that cannot be read, parsed or accepted.
    Scene {
        /// The file (or the name of the built-in scene).
        file: String,
        /// What is wrong, naming the key or line, and what is valid.
        message: String,
    },
    /// Options that cannot work together.
    Usage(String),
    /// A file or folder that cannot be written.
    Output {
        /// The path that failed.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// Ctrl-C (or SIGTERM) arrived before the files were renamed into place.
    Interrupted,
    /// Ctrl-C (or SIGTERM) stopped a command that writes no files (`raystep
    /// serve`), after it closed cleanly: what it says.
    Stopped(&'static str),
}

impl Error {
    /// The exit code: [`USER_ERROR`] for a mistake, 130 after an interrupt.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Interrupted | Error::Stopped(_) => crate::interrupt::EXIT_CODE,
            _ => USER_ERROR as u8,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Scene { file, message } => write!(f, "{file}: {message}"),
            Error::Usage(message) => f.write_str(message),
            Error::Output { path, message } => {
                write!(f, "cannot write {}: {message}", path.display())
            }
            Error::Interrupted => f.write_str(
                "interrupted: nothing was written, and the files of the render before \
                 are as they were",
            ),
            Error::Stopped(what) => write!(f, "interrupted: {what}"),
        }
    }
}

impl std::error::Error for Error {}

/// `Err(Error::Interrupted)` once an interrupt has been asked for
/// ([`crate::interrupt`]).
pub fn check_interrupt() -> Result<(), Error> {
    if crate::interrupt::requested() {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}
