//! The `raystep` binary: parse the command line, run it, turn errors into messages
//! and exit codes (0 done, 1 `diff` of images that differ, 2 a mistake in the
//! input or trouble, as clap does for bad flags, 130 interrupted).

use std::process::ExitCode;

use clap::Parser;
use raystep::tools::args::Cli;
use raystep::tools::cli::execute;

fn main() -> ExitCode {
    let cli = Cli::parse();
    raystep::interrupt::install();
    match execute(cli) {
        Ok(code) => ExitCode::from(code),
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::from(error.exit_code())
        }
    }
}
