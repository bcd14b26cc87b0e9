//! The `meshpaint` command line: parses the arguments, runs the command ([`cli`]), and
//! turns errors into messages and exit codes.

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // The editor words errors the same way: one line, causes it already quotes skipped.
            eprintln!("error: {}", meshpaint::app::text::error_text(&error));
            ExitCode::FAILURE
        }
    }
}
