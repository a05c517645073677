//! The `accelcal` command: parses the command line, runs it, prints the error chain.

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = accelcal::cli::Cli::parse();
    match accelcal::app::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(accelcal::app::exit_code(&err))
        }
    }
}
