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
            ExitCode::from(commands::exit_code(&err).max(output_exit_code(&err)))
        }
    }
}

/// 2 when `err` is an output that cannot be written (a path that is a directory, in a missing
/// or read-only directory, a full device): the user's to fix, like bad input; 0 otherwise.
/// Results are written only through [`accelcal::output`], so an operating system's error that
/// reaches here is one of an output's.
fn output_exit_code(err: &anyhow::Error) -> u8 {
    let output = err
        .chain()
        .any(|e| e.is::<accelcal::output::OutputError>() || e.is::<std::io::Error>());
    if output { 2 } else { 0 }
}
