//! The `raystep` binary: parse the command line, run it, turn errors into messages
//! and exit codes (0 done, 1 `diff` of images that differ, 2 a mistake in the
//! input or trouble, as clap does for bad flags, 130 interrupted).

use std::process::ExitCode;

use clap::Parser;
use raystep::tools::args::Cli;
use raystep::tools::cli::execute;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // `--help` and `--version` (on standard output), or a mistake in the
        // flags (on standard error, exit 2). Help that cannot be written (a full
        // disk) is an error, as for any output; a closed pipe is not.
        Err(e) => {
            use std::io::Write;
            if let Some(scene) = scene_given_as_command(&e) {
                raystep::error::to_stderr(format_args!(
                    "error: `{scene}` is not a command; to render a scene file, name the \
                     command first: `raystep stages {scene}` (every stage) or `raystep \
                     render {scene}`"
                ));
                return ExitCode::from(raystep::error::USER_ERROR as u8);
            }
            let printed = e.print().and_then(|()| std::io::stdout().flush());
            return match printed {
                Err(io) if io.kind() != std::io::ErrorKind::BrokenPipe => {
                    let error = raystep::error::Error::Output {
                        path: "standard output".into(),
                        message: io.to_string(),
                    };
                    raystep::error::to_stderr(format_args!("error: {error}"));
                    ExitCode::from(error.exit_code())
                }
                _ => ExitCode::from(e.exit_code() as u8),
            };
        }
    };
    raystep::interrupt::install();
    match execute(cli) {
        Ok(code) => ExitCode::from(code),
        Err(error) => {
            raystep::error::to_stderr(format_args!("error: {error}"));
            ExitCode::from(error.exit_code())
        }
    }
}

/// The scene file a command line gave where the command goes (`raystep
/// seed.toml`): the word clap calls an unrecognised subcommand, if it names a
/// `.toml` file or an existing file.
fn scene_given_as_command(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::InvalidSubcommand {
        return None;
    }
    let Some(ContextValue::String(word)) = e.get(ContextKind::InvalidSubcommand) else {
        return None;
    };
    (word.ends_with(".toml") || std::path::Path::new(word).is_file()).then(|| word.clone())
}
