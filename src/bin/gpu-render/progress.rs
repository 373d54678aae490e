//! Render progress on stderr, only for renders that take longer than a second.
//!
//! On a terminal the line is redrawn in place (`\r`) at most ten times a second; when
//! stderr is a file or a pipe, a plain line is printed each time another 10% is done,
//! so a log gets at most about ten lines. Nothing is ever written to stdout.

use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Renders shorter than this print no progress at all.
const QUIET_PERIOD: Duration = Duration::from_secs(1);
/// Smallest interval between two redraws of the terminal line.
const REDRAW_INTERVAL: Duration = Duration::from_millis(100);

/// Reports the progress of one render pass. Shared by the tracer's worker threads.
pub struct Progress {
    label: String,
    enabled: bool,
    terminal: bool,
    start: Instant,
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    /// Last percentage printed as a plain line (multiples of 10).
    last_step: u32,
    /// When the terminal line was last drawn, if it was.
    last_draw: Option<Instant>,
    /// Whether the last terminal line drawn showed every row done.
    drew_complete: bool,
    /// Largest row count seen (reports may arrive out of order from worker threads).
    rows_done: u32,
    rows_total: u32,
}

impl Progress {
    /// A reporter for the pass called `label`; `enabled = false` makes it silent.
    pub fn new(label: impl Into<String>, enabled: bool) -> Self {
        Self {
            label: label.into(),
            enabled,
            terminal: std::io::stderr().is_terminal(),
            start: Instant::now(),
            state: Mutex::new(State::default()),
        }
    }

    /// Records that `done` of `total` rows are finished and prints if it is time to.
    pub fn update(&self, done: u32, total: u32) {
        if !self.enabled || total == 0 {
            return;
        }
        let now = Instant::now();
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.rows_done = state.rows_done.max(done.min(total));
        state.rows_total = total;
        if now.duration_since(self.start) < QUIET_PERIOD {
            return;
        }
        let percent = percent(state.rows_done, total);
        if self.terminal {
            let due = state
                .last_draw
                .is_none_or(|t| now.duration_since(t) >= REDRAW_INTERVAL);
            if due || state.rows_done == total {
                state.last_draw = Some(now);
                state.drew_complete = state.rows_done == total;
                self.draw_line(percent, state.rows_done, total, "");
            }
        } else {
            let step = percent / 10 * 10;
            if step > state.last_step {
                state.last_step = step;
                self.draw_line(percent, state.rows_done, total, "\n");
            }
        }
    }

    /// Ends the pass: completes and ends the terminal line if one was drawn.
    pub fn finish(&self) {
        if !self.enabled || !self.terminal {
            return;
        }
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if state.drew_complete {
            let _ = writeln!(std::io::stderr());
        } else if state.last_draw.is_some() {
            let total = state.rows_total;
            self.draw_line(100, total, total, "\n");
        }
    }

    fn draw_line(&self, percent: u32, done: u32, total: u32, end: &str) {
        let start = if self.terminal { "\r\x1b[2K" } else { "" };
        let elapsed = self.start.elapsed().as_secs_f64();
        let mut stderr = std::io::stderr().lock();
        // Progress is best effort: a closed stderr must not stop the render.
        let _ = write!(
            stderr,
            "{start}{}: {percent:3}% ({done}/{total} rows, {elapsed:.1} s){end}",
            self.label
        );
        let _ = stderr.flush();
    }
}

fn percent(done: u32, total: u32) -> u32 {
    (u64::from(done) * 100 / u64::from(total.max(1))) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_rounds_down_and_handles_extremes() {
        assert_eq!(percent(0, 240), 0);
        assert_eq!(percent(239, 240), 99);
        assert_eq!(percent(240, 240), 100);
        assert_eq!(percent(u32::MAX, u32::MAX), 100);
    }

    #[test]
    fn disabled_reporter_is_silent_and_safe() {
        let progress = Progress::new("test", false);
        progress.update(1, 2);
        progress.update(2, 0);
        progress.finish();
    }
}
