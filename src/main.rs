//! The `meshpaint` command line: parses the arguments, runs the command ([`cli`]), and
//! turns errors into messages and exit codes.

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    restore_default_sigpipe();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = cli::Cli::parse();
    // This thread works in the parallel calls it makes instead of waiting for a pool
    // (`meshpaint_core::threads`); if that pool cannot be set up, the global pool still works.
    if let Err(error) = meshpaint_core::threads::init() {
        log::warn!("thread pool: {error}");
    }
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // The editor words errors the same way: one line, causes it already quotes skipped.
            eprintln!("error: {}", meshpaint::app::text::error_text(&error));
            ExitCode::FAILURE
        }
    }
}

/// `meshpaint info FILE | head` ends quietly when `head` stops reading, as Unix tools do:
/// Rust ignores SIGPIPE, so `println!` would panic on the closed pipe instead.
#[cfg(unix)]
fn restore_default_sigpipe() {
    // SAFETY: called first in `main`, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn restore_default_sigpipe() {}
