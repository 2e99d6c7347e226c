//! The `raystep` binary: parse the command line, run it, turn errors into messages
//! and exit codes (0 done, 2 a mistake in the input, as clap does for bad flags).

use std::process::ExitCode;

use clap::Parser;
use raystep::cli::{run, Cli};
use raystep::error::USER_ERROR;

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::from(USER_ERROR as u8)
        }
    }
}
