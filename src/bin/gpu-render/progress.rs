//! Render and scene-loading progress on stderr, only for work that takes longer than a
//! second.
//!
//! On a terminal the line is redrawn in place (`\r`) at most ten times a second; when
//! stderr is a file or a pipe, a plain line is printed each time another 10% is done
//! (and, while loading, each time the loader moves on to its next stage), so a log
//! gets at most about ten lines per pass. Nothing is ever written to stdout.

use std::io::{IsTerminal, Write};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

use gpu_render::scene::LoadProgress;

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

/// Runs `load` with a progress hook that, once loading has taken a second, shows on
/// stderr what the loader is doing (reading, parsing, checking n of m items). The
/// parser reports nothing while it parses, so a watcher thread keeps the line alive.
pub fn while_loading<T>(
    label: &str,
    enabled: bool,
    load: impl FnOnce(&(dyn Fn(LoadProgress) + Sync)) -> T,
) -> T {
    if !enabled {
        return load(&|_| {});
    }
    let latest: Mutex<Option<LoadProgress>> = Mutex::new(None);
    let finished = (Mutex::new(false), Condvar::new());
    let hook = |progress: LoadProgress| {
        *latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(progress);
    };
    std::thread::scope(|scope| {
        scope.spawn(|| watch_loading(label, &latest, &finished));
        let result = load(&hook);
        let (done, wake) = &finished;
        *done.lock().unwrap_or_else(|e| e.into_inner()) = true;
        wake.notify_all();
        result
    })
}

/// The watcher of [`while_loading`]: prints the latest stage until told to stop.
fn watch_loading(
    label: &str,
    latest: &Mutex<Option<LoadProgress>>,
    (finished, wake): &(Mutex<bool>, Condvar),
) {
    let start = Instant::now();
    let terminal = std::io::stderr().is_terminal();
    let mut printed: Option<(LoadProgress, u64)> = None;
    let mut done = finished.lock().unwrap_or_else(|e| e.into_inner());
    while !*done {
        done = wake
            .wait_timeout(done, REDRAW_INTERVAL)
            .unwrap_or_else(|e| e.into_inner())
            .0;
        let elapsed = start.elapsed();
        if *done || elapsed < QUIET_PERIOD {
            continue;
        }
        let Some(now) = *latest.lock().unwrap_or_else(|e| e.into_inner()) else {
            continue;
        };
        let step = load_step(now);
        let due = terminal
            || printed.is_none_or(|(last, last_step)| {
                std::mem::discriminant(&last) != std::mem::discriminant(&now) || step > last_step
            });
        if due {
            let (start_line, end) = if terminal {
                ("\r\x1b[2K", "")
            } else {
                ("", "\n")
            };
            let mut stderr = std::io::stderr().lock();
            // Best effort, as for render progress.
            let _ = write!(
                stderr,
                "{start_line}loading {label}: {} ({:.1} s){end}",
                describe_load(now),
                elapsed.as_secs_f64()
            );
            let _ = stderr.flush();
            printed = Some((now, step));
        }
    }
    if terminal && printed.is_some() {
        let _ = writeln!(std::io::stderr());
    }
}

/// Tenths of the checking stage done (0 for the other stages).
fn load_step(progress: LoadProgress) -> u64 {
    match progress {
        LoadProgress::Checking { done, total } | LoadProgress::Importing { done, total } => {
            done * 10 / total.max(1)
        }
        _ => 0,
    }
}

fn describe_load(progress: LoadProgress) -> String {
    let megabytes = |bytes: u64| bytes as f64 / 1e6;
    match progress {
        LoadProgress::Reading { bytes } => format!("reading {:.1} MB", megabytes(bytes)),
        LoadProgress::Parsing { bytes } => format!("parsing {:.1} MB of TOML", megabytes(bytes)),
        LoadProgress::Checking { done, total } => format!(
            "checking items {:3}% ({done}/{total})",
            done * 100 / total.max(1)
        ),
        LoadProgress::Importing { done, total } => format!(
            "reading the model {:3}% ({:.1} of {:.1} MB)",
            done * 100 / total.max(1),
            megabytes(done),
            megabytes(total)
        ),
        _ => "working".to_owned(),
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
    fn load_stages_are_described() {
        assert_eq!(
            describe_load(LoadProgress::Parsing { bytes: 63_000_000 }),
            "parsing 63.0 MB of TOML"
        );
        assert_eq!(
            describe_load(LoadProgress::Checking { done: 1, total: 4 }),
            "checking items  25% (1/4)"
        );
        assert_eq!(
            describe_load(LoadProgress::Importing {
                done: 50_000_000,
                total: 200_000_000
            }),
            "reading the model  25% (50.0 of 200.0 MB)"
        );
        assert_eq!(
            load_step(LoadProgress::Checking {
                done: 99,
                total: 100
            }),
            9
        );
    }

    #[test]
    fn loading_returns_what_the_loader_returns() {
        let value = while_loading("x", true, |hook| {
            hook(LoadProgress::Reading { bytes: 1 });
            42
        });
        assert_eq!(value, 42);
        assert_eq!(while_loading("x", false, |_| 7), 7);
    }

    #[test]
    fn disabled_reporter_is_silent_and_safe() {
        let progress = Progress::new("test", false);
        progress.update(1, 2);
        progress.update(2, 0);
        progress.finish();
    }
}
