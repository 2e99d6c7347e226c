//! The `raystep` binary: parse the command line, run it, turn errors into messages
//! and exit codes (0 done, 2 a mistake in the input, as clap does for bad flags, 130
//! interrupted).

use std::process::ExitCode;

use clap::Parser;
use raystep::tools::cli::{run, Cli};

fn main() -> ExitCode {
    let cli = Cli::parse();
    raystep::interrupt::install();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::from(error.exit_code())
        }
    }
}
