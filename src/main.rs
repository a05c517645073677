//! The `accelcal` command: parses the command line, runs it, prints the error chain.

mod cli;
mod commands;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    // Without the handlers a run still works; only an interrupted one may leave temporaries.
    let _ = accelcal::output::remove_temporaries_on_signals();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(commands::exit_code(&err))
        }
    }
}
