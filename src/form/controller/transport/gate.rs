//! The e-stop path: every packet the host sends goes through its link's [`Gate`], and an
//! emergency stop is one call on that gate, from any thread.
//!
//! A gate holds the link's sending half behind a lock that is held for one frame's write at
//! most (each link's writes are bounded by its write timeout), so an e-stop waits for at most
//! the frame being written — never for the session's task, its runtime, a progress bar or a
//! log. [`Gate::emergency_stop`] latches the gate first and then broadcasts `EmergencyStop`
//! [`EMERGENCY_STOP_REPEATS`] times (against a lossy bus); from the latch on, every other
//! packet is refused with [`TransportError::Stopped`], so nothing the session does afterwards
//! (a FaultReset, an Enable, a target) can undo the stop. Whoever waits on
//! [`Gate::watch`] learns of the stop once the frames are out.
//!
//! The callers: the local control endpoint ([`crate::form::controller::control`], `dressform estop`
//! from another terminal), the command line's signal thread (SIGINT, SIGTERM, SIGHUP), and
//! [`crate::form::controller::emergency_stop`] on a link the caller opened itself.

use std::fmt;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use firmware_protocol::{Message, Packet};
use tokio::sync::watch;

use super::TransportError;

/// How many times an emergency stop is broadcast: nodes act on the first that arrives, and
/// three make a frame lost on a 5 %-lossy bus a one-in-8000 event.
pub const EMERGENCY_STOP_REPEATS: usize = 3;

/// The sending half of a link: writes one packet as one whole frame.
pub trait PacketSink: Send {
    /// Writes `packet`; returns once the frame is handed to the device (bounded by the link's
    /// write timeout).
    fn write(&mut self, packet: &Packet) -> Result<(), TransportError>;
}

/// Who stopped the form.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopCause {
    /// `dressform estop` from another terminal, through the control endpoint.
    Remote,
    /// A signal to this process (`SIGINT`, `SIGTERM`, `SIGHUP`).
    Signal(&'static str),
    /// This process's own request ([`crate::form::controller::emergency_stop`]).
    Requested,
}

impl fmt::Display for StopCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Remote => f.write_str("an e-stop from another terminal"),
            Self::Signal("SIGINT") => f.write_str("Ctrl-C (SIGINT)"),
            Self::Signal(name) => f.write_str(name),
            Self::Requested => f.write_str("an e-stop request"),
        }
    }
}

/// The sink and the latch, under one lock.
struct Guarded {
    sink: Box<dyn PacketSink>,
    stopped: Option<StopCause>,
}

struct Inner {
    device: String,
    guarded: Mutex<Guarded>,
    /// Told once the e-stop frames are out.
    watch: watch::Sender<Option<StopCause>>,
}

/// A link's sending half, shared by the session and the e-stop (cheap to clone).
#[derive(Clone)]
pub struct Gate {
    inner: Arc<Inner>,
}

impl fmt::Debug for Gate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Gate")
            .field("device", &self.inner.device)
            .field("stopped", &self.stopped())
            .finish_non_exhaustive()
    }
}

impl Gate {
    /// A gate on `device` sending through `sink`.
    pub fn new(device: impl Into<String>, sink: impl PacketSink + 'static) -> Self {
        let (watch, _) = watch::channel(None);
        let guarded = Mutex::new(Guarded { sink: Box::new(sink), stopped: None });
        Self { inner: Arc::new(Inner { device: device.into(), guarded, watch }) }
    }

    fn lock(&self) -> MutexGuard<'_, Guarded> {
        // A panic while writing leaves the sink usable: the e-stop must still get through.
        self.inner.guarded.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The device's name.
    pub fn device(&self) -> &str {
        &self.inner.device
    }

    /// Sends `packet`, unless the link was e-stopped.
    pub fn send(&self, packet: &Packet) -> Result<(), TransportError> {
        let mut guarded = self.lock();
        if let Some(cause) = guarded.stopped {
            return Err(TransportError::Stopped { device: self.inner.device.clone(), cause });
        }
        guarded.sink.write(packet)
    }

    /// Latches the gate (refusing every later packet but e-stops) and broadcasts
    /// `EmergencyStop` [`EMERGENCY_STOP_REPEATS`] times; the first cause is kept. Fails only
    /// if no frame could be written.
    pub fn emergency_stop(&self, cause: StopCause) -> Result<(), TransportError> {
        let result = {
            let mut guarded = self.lock();
            guarded.stopped.get_or_insert(cause);
            let stop = Packet::broadcast(Message::EmergencyStop);
            let results: Vec<_> =
                (0..EMERGENCY_STOP_REPEATS).map(|_| guarded.sink.write(&stop)).collect();
            let any_sent = results.iter().any(Result::is_ok);
            results.into_iter().find(|r| r.is_err() && !any_sent).unwrap_or(Ok(()))
        };
        let cause = self.stopped();
        self.inner.watch.send_replace(cause);
        result
    }

    /// Why the link was e-stopped, if it was.
    pub fn stopped(&self) -> Option<StopCause> {
        self.lock().stopped
    }

    /// Changes once an e-stop's frames are out.
    pub fn watch(&self) -> watch::Receiver<Option<StopCause>> {
        self.inner.watch.subscribe()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_protocol::NodeId;

    /// Records what it writes; fails every write when `broken`.
    struct Recorder(Arc<Mutex<Vec<Packet>>>, bool);

    impl PacketSink for Recorder {
        fn write(&mut self, packet: &Packet) -> Result<(), TransportError> {
            if self.1 {
                return Err(TransportError::Closed("test".into()));
            }
            self.0.lock().unwrap().push(*packet);
            Ok(())
        }
    }

    #[test]
    fn after_an_emergency_stop_only_emergency_stops_go_out() {
        let sent = Arc::new(Mutex::new(Vec::new()));
        let gate = Gate::new("test", Recorder(Arc::clone(&sent), false));
        let mut watch = gate.watch();
        let enable = Packet::node(
            NodeId::new(1).unwrap(),
            Message::Control(firmware_protocol::drive::DriveCommand::FaultReset),
        );
        gate.send(&enable).unwrap();
        gate.emergency_stop(StopCause::Remote).unwrap();
        assert!(watch.has_changed().unwrap());
        assert_eq!(*watch.borrow_and_update(), Some(StopCause::Remote));
        let refused = gate.send(&enable).unwrap_err();
        assert!(refused.to_string().contains("an e-stop from another terminal"), "{refused}");
        // A second stop sends again and keeps the first cause.
        gate.emergency_stop(StopCause::Signal("SIGTERM")).unwrap();
        assert_eq!(gate.stopped(), Some(StopCause::Remote));
        let sent = sent.lock().unwrap();
        assert_eq!(sent.len(), 1 + 2 * EMERGENCY_STOP_REPEATS);
        assert!(sent[1..].iter().all(|p| *p == Packet::broadcast(Message::EmergencyStop)));
    }

    #[test]
    fn a_link_that_cannot_write_reports_the_failed_stop() {
        let gate = Gate::new("test", Recorder(Arc::default(), true));
        assert!(gate.emergency_stop(StopCause::Requested).is_err());
        assert_eq!(gate.stopped(), Some(StopCause::Requested));
    }
}
