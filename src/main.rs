//! The `accelcal` command: parses the command line, runs it, prints the error chain.

mod cli;
mod commands;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    // Without the handlers a run still works; only an interrupted one may leave temporaries.
    let _ = accelcal::output::remove_temporaries_on_signals(commands::end_as_signal);
    let result = commands::run(cli);
    commands::tell_stale_temporaries_removed();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(commands::exit_code(&err))
        }
    }
}
