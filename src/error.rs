//! Errors a user can cause, each a message that says what is wrong and what would
//! be valid. The command line prints them and exits with [`USER_ERROR`] (130 after
//! an interrupt).

use std::borrow::Cow;
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

/// `text` safe to print on a terminal: every control character but newline and
/// tab shown as its Unicode control picture (`ESC` as `␛`, `DEL` as `␡`) and the
/// C1 controls (U+0080–U+009F) as `�`. A scene file or a file name quoted in a
/// message then cannot clear the screen, set the window's title or move the
/// cursor, and each character still takes one column, so the `^` under a quoted
/// line stays under its place.
pub fn for_terminal(text: &str) -> Cow<'_, str> {
    let unsafe_char = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.contains(unsafe_char) {
        return Cow::Borrowed(text);
    }
    text.chars()
        .map(|c| match c {
            '\u{7f}' => '\u{2421}',
            c if unsafe_char(c) && u32::from(c) < 0x20 => {
                char::from_u32(0x2400 + u32::from(c)).unwrap_or('\u{fffd}')
            }
            c if unsafe_char(c) => '\u{fffd}',
            c => c,
        })
        .collect()
}

/// Write `text` as one line on standard error, through [`for_terminal`]: every
/// message, warning and status line raystep prints there. A line that cannot be
/// written is dropped (`eprintln!` would panic on a closed standard error).
pub fn to_stderr(text: std::fmt::Arguments) {
    use std::io::Write;
    let text = text.to_string();
    let _ = writeln!(std::io::stderr().lock(), "{}", for_terminal(&text));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ESC, BEL, CR, NUL, DEL and CSI (U+009B) never reach the terminal; newline,
    /// tab and every printable character (accents, `…`, `^`) do, unchanged.
    #[test]
    fn control_characters_are_shown_not_obeyed() {
        assert_eq!(
            for_terminal("a # \u{1b}[2J\u{1b}]0;pwned\u{7}\r\0\u{7f}\u{9b}"),
            "a # \u{241b}[2J\u{241b}]0;pwned\u{2407}\u{240d}\u{2400}\u{2421}\u{fffd}"
        );
        let plain = "line 2, column 9: é … ^\n\t2 | x";
        assert!(matches!(for_terminal(plain), Cow::Borrowed(p) if p == plain));
        // One character each: a caret under the line stays under its place.
        let line = "x = 1 # \u{1b}\u{1b} y";
        assert_eq!(for_terminal(line).chars().count(), line.chars().count());
    }
}
