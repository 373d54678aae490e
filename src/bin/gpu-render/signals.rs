//! Ctrl-C and termination: SIGINT, SIGTERM and SIGHUP (on Windows, Ctrl-C, Ctrl-Break
//! and closing the console) stop the program cleanly; a second signal ends it at once.
//!
//! The first signal removes the temporary file of every output being written
//! ([`gpu_render::output::cancel_pending_writes`]), so no `.gpu-render-*.tmp` stays
//! behind and no existing output is replaced by a partial one, says so on stderr and
//! exits with status 130 (128 + SIGINT, whichever signal it was). A render in progress
//! is simply abandoned: nothing of it is on disk yet. Should that cleanup ever hang,
//! a second signal exits with status 130 immediately, running nothing.

use std::sync::atomic::{AtomicU32, Ordering};

use anyhow::{Context, Result};

/// The exit status after an interruption: 128 + SIGINT, as shells report Ctrl-C.
pub const EXIT_INTERRUPTED: i32 = 130;

/// Signals received so far.
static SIGNALS: AtomicU32 = AtomicU32::new(0);

/// Installs the handler; call it first thing, before any file is written.
pub fn install() -> Result<()> {
    ctrlc::set_handler(|| {
        if SIGNALS.fetch_add(1, Ordering::SeqCst) > 0 {
            exit_now();
        }
        // The cleanup runs on its own thread so that this handler returns at once and
        // can see a second signal while the cleanup waits (for a rename in progress).
        std::thread::spawn(|| {
            let removed = gpu_render::output::cancel_pending_writes();
            let detail = match removed {
                0 => String::new(),
                1 => "; removed the unfinished output file".to_owned(),
                n => format!("; removed {n} unfinished output files"),
            };
            // A progress line on a terminal may be unfinished: start a new line.
            eprintln!("\ninterrupted{detail}; no output is left half-written");
            std::process::exit(EXIT_INTERRUPTED);
        });
    })
    .context("cannot install the Ctrl-C/termination signal handler")
}

/// Ends the process now, without running exit handlers or destructors.
fn exit_now() -> ! {
    #[cfg(unix)]
    {
        // SAFETY: `_exit` is async-signal-safe, takes no pointers and does not return.
        unsafe { libc::_exit(EXIT_INTERRUPTED) }
    }
    #[cfg(not(unix))]
    std::process::exit(EXIT_INTERRUPTED)
}
