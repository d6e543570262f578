//! SIGINT, SIGTERM and SIGHUP e-stop every link this process owns, before it exits.
//!
//! A thread of its own waits for the signals (`signal-hook`), so a busy runtime, a blocked
//! terminal or a full disk cannot delay the stop: it calls [`Gate::emergency_stop`] on every
//! armed link; the session there ends with "stopped by SIGTERM" and the command exits 1.
//! Should the process not end within [`GRACE`], or a second signal come, it exits at once
//! (the form is already stopped). With no link armed, a signal does what it does by default,
//! unless the command asked to finish its work first ([`finish_on_signal`]: `watch` ends the
//! scan in hand, its outputs committed as a whole); a second signal then ends it at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, OnceLock, PoisonError};
use std::time::Duration;

use dressform::form::controller::{Gate, StopCause};
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use signal_hook::low_level::emulate_default_handler;

/// How long the process may take to end after a signal stopped the form.
const GRACE: Duration = Duration::from_secs(2);

/// The exit status after a signal stopped the form: the form failed (README.md#exit-status).
const STOPPED: i32 = 1;

/// The armed links, each with the number of its [`Armed`] guard.
static ARMED: Mutex<Vec<(u64, Gate)>> = Mutex::new(Vec::new());

/// Set once the watching thread runs (or could not be started).
static WATCHING: OnceLock<()> = OnceLock::new();

/// Whether the command asked to finish its work on a signal ([`finish_on_signal`]).
static FINISH_ASKED: AtomicBool = AtomicBool::new(false);

/// Set by the first signal when [`FINISH_ASKED`].
static FINISHING: AtomicBool = AtomicBool::new(false);

/// From now on, the first SIGINT, SIGTERM or SIGHUP with no link armed sets the flag returned
/// (the command finishes what it is doing, then ends) instead of ending the process; a
/// signal while a link is armed e-stops it as always, and sets the flag too.
pub fn finish_on_signal() -> &'static AtomicBool {
    FINISH_ASKED.store(true, Ordering::SeqCst);
    WATCHING.get_or_init(watch);
    &FINISHING
}

/// A link armed for signals; disarmed when dropped.
#[must_use = "the link is disarmed when this is dropped"]
pub struct Armed(u64);

impl Drop for Armed {
    fn drop(&mut self) {
        armed().retain(|(id, _)| *id != self.0);
    }
}

fn armed() -> std::sync::MutexGuard<'static, Vec<(u64, Gate)>> {
    ARMED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Arms `gate`: until the guard is dropped, SIGINT, SIGTERM and SIGHUP e-stop it.
pub fn arm(gate: &Gate) -> Armed {
    WATCHING.get_or_init(watch);
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    armed().push((id, gate.clone()));
    Armed(id)
}

/// Starts the thread that turns signals into e-stops.
fn watch() {
    let mut signals = match Signals::new([SIGINT, SIGTERM, SIGHUP]) {
        Ok(signals) => signals,
        Err(e) => {
            // The process then ends on a signal as by default: the nodes' watchdogs stop
            // the form within 300 ms.
            errln!("warning: cannot watch for signals ({e}): a signal will not send an e-stop");
            return;
        }
    };
    let spawned = std::thread::Builder::new().name("dressform signals".into()).spawn(move || {
        let mut stopped = false;
        for signal in signals.forever() {
            let gates: Vec<Gate> = armed().iter().map(|(_, g)| g.clone()).collect();
            let finishing = FINISHING.swap(true, Ordering::SeqCst);
            if gates.is_empty() && FINISH_ASKED.load(Ordering::SeqCst) && !finishing {
                errln!(
                    "{}: finishing the scan in hand, then stopping (signal again to stop at once)",
                    name(signal)
                );
                continue;
            }
            if gates.is_empty() {
                // Nothing to stop: end as the signal would have ended the process.
                let _ = emulate_default_handler(signal);
                std::process::exit(128 + signal);
            }
            if stopped {
                std::process::exit(STOPPED);
            }
            stopped = true;
            let cause = StopCause::Signal(name(signal));
            for gate in gates {
                if let Err(e) = gate.emergency_stop(cause) {
                    errln!("error: {e}");
                }
            }
            std::thread::spawn(|| {
                std::thread::sleep(GRACE);
                std::process::exit(STOPPED);
            });
        }
    });
    if let Err(e) = spawned {
        errln!("warning: cannot watch for signals ({e}): a signal will not send an e-stop");
    }
}

fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        _ => "SIGHUP",
    }
}
