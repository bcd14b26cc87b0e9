//! A one-line progress bar on stderr, drawn only when stderr is a terminal (so logs, pipes
//! and CI output stay clean): `[#########...........]  42 % stage`. Shared by the commands
//! with long conversions (`convert`; `pack` and `open` can take it too): [`ProgressBar::set`]
//! takes `&self`, so a `Fn(&str, f32) + Sync` progress callback can call it from any thread.
//!
//! `MESHPAINT_PROGRESS=always` draws it even when stderr is not a terminal (to see it in a
//! test or a log), `never` hides it; anything else (or unset) decides by the terminal.

use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Characters of the bar between the brackets.
const BAR_WIDTH: usize = 30;
/// Redraws at most this often (a terminal write per sample would cost more than the work).
const REDRAW: Duration = Duration::from_millis(100);

/// The bar (module docs).
#[derive(Debug)]
pub(super) struct ProgressBar {
    enabled: bool,
    state: Mutex<State>,
}

#[derive(Debug)]
struct State {
    last_draw: Option<Instant>,
    fraction: f32,
    /// Characters of the line last drawn (to clear it).
    drawn: usize,
}

impl ProgressBar {
    /// A bar drawn when stderr is a terminal (or as `MESHPAINT_PROGRESS` says).
    pub(super) fn new() -> ProgressBar {
        let enabled = match std::env::var("MESHPAINT_PROGRESS").as_deref() {
            Ok("always") => true,
            Ok("never") => false,
            _ => std::io::stderr().is_terminal(),
        };
        ProgressBar { enabled, state: Mutex::new(State { last_draw: None, fraction: 0.0, drawn: 0 }) }
    }

    /// Whether anything is drawn.
    #[allow(dead_code)] // for commands that print differently with a bar
    pub(super) fn enabled(&self) -> bool {
        self.enabled
    }

    /// Shows `fraction` (0..1, clamped; never moves backwards) done, in `stage`.
    pub(super) fn set(&self, fraction: f32, stage: &str) {
        if !self.enabled {
            return;
        }
        let mut state = self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let fraction = if fraction.is_finite() { fraction.clamp(0.0, 1.0) } else { 0.0 };
        state.fraction = state.fraction.max(fraction);
        let now = Instant::now();
        if state.last_draw.is_some_and(|last| now.duration_since(last) < REDRAW) && fraction < 1.0 {
            return;
        }
        state.last_draw = Some(now);
        let line = line(state.fraction, stage);
        let clear = " ".repeat(state.drawn.saturating_sub(line.chars().count()));
        state.drawn = line.chars().count();
        let mut stderr = std::io::stderr().lock();
        // A failed write to stderr has nowhere to be reported.
        let _ = write!(stderr, "\r{line}{clear}");
        let _ = stderr.flush();
    }

    /// Prints `text` as a line of its own on stderr, above the bar.
    pub(super) fn println(&self, text: &str) {
        let mut state = self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let mut stderr = std::io::stderr().lock();
        if self.enabled && state.drawn > 0 {
            let _ = write!(stderr, "\r{}\r", " ".repeat(state.drawn));
            state.drawn = 0;
            state.last_draw = None;
        }
        let _ = writeln!(stderr, "{text}");
    }

    /// Clears the bar (the terminal line is left empty).
    pub(super) fn finish(&self) {
        if !self.enabled {
            return;
        }
        let mut state = self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if state.drawn > 0 {
            let mut stderr = std::io::stderr().lock();
            let _ = write!(stderr, "\r{}\r", " ".repeat(state.drawn));
            let _ = stderr.flush();
            state.drawn = 0;
        }
    }
}

impl Drop for ProgressBar {
    fn drop(&mut self) {
        self.finish();
    }
}

/// The text of the bar at `fraction` in `stage` (no carriage return).
fn line(fraction: f32, stage: &str) -> String {
    let filled = ((fraction * BAR_WIDTH as f32).round() as usize).min(BAR_WIDTH);
    let stage: String = stage.chars().take(60).collect();
    format!("[{}{}] {:3.0} % {stage}", "#".repeat(filled), ".".repeat(BAR_WIDTH - filled), fraction * 100.0)
}
