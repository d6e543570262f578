//! An in-process CAN bus: many ports, arbitration by identifier, frame times from the bit
//! rate, bus-load accounting, faults and a candump log. Deterministic under tokio's paused
//! clock.
//!
//! **Timing.** The bus keeps an exact timeline of its own (nanoseconds): a frame queued at
//! `q` can start one bit time later, when the bus is free; it then occupies the bus for
//! [`budget::Bus::frame_time_ns`] (worst-case stuffing, interframe space included) and is
//! received by every other port at its end. When several frames can start at the same moment
//! the one with the **lowest identifier wins** arbitration (ties, which the protocol never
//! makes, go to the lower port number); the losers compete again at the end of the frame,
//! together with whatever was queued meanwhile. Each port queues its frames in order (like a
//! SocketCAN socket): only its oldest frame competes, so a host's set-points stay before its
//! SYNC. Tasks wake on tokio's timer, which has millisecond resolution: a frame is handed
//! to the receivers at the first timer tick at or after its end, stamped with its exact end
//! ([`Received::at`]), and the bus timeline, the load and the log stay exact.
//!
//! **Load.** [`CanBus::stats`] counts frames and the bus time they used ([`BusStats`]);
//! the host benchmark reads the load from it.
//!
//! **Frames.** A port sends and receives [`firmware_protocol::can::Frame`]s (standard ids,
//! classic or FD). On a classic bus an FD frame is refused
//! ([`BusError::FdOnClassicBus`]: a classic controller would destroy it with error frames).
//! A sender does not receive its own frames.
//!
//! **Faults** ([`crate::fault`]): a dropped frame takes its bus time but reaches nobody; a
//! corrupted one is cut short by an error frame (logged) and retransmitted; `delay` hands
//! frames to receivers later; during a bus-off window every queued frame fails with
//! [`BusError::BusOff`].
//!
//! **Receivers** hold up to [`RX_QUEUE`] frames; a port that does not read loses the newest
//! frames (an overrun, counted in [`BusStats::overruns`]).

use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use embedded_can::Frame as _;
use firmware_protocol::can::Frame;
use firmware_protocol::{Link, budget};
use tokio::sync::{Notify, mpsc, oneshot};
use tokio::task::JoinHandle;
use tokio::time::{Duration, Instant, sleep_until};

use super::candump::CandumpLog;
use crate::fault::{BusFaultInjector, FaultSpec, FrameFault};

/// How many received frames a port holds before it overruns.
pub const RX_QUEUE: usize = 4096;

/// Bits an error frame costs after the bit error: error flag and echo (up to 12), error
/// delimiter (8), intermission (3).
const ERROR_FRAME_BITS: u64 = 23;

/// The kind and speed of a CAN bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CanKind {
    /// Classic CAN at `bitrate` bit/s.
    Classic {
        /// Bit rate, bit/s.
        bitrate: u32,
    },
    /// CAN FD: arbitration at `nominal`, data phase at `data` bit/s.
    Fd {
        /// Nominal bit rate, bit/s.
        nominal: u32,
        /// Data-phase bit rate, bit/s.
        data: u32,
    },
}

impl CanKind {
    /// Classic CAN at 1 Mbit/s, the protocol's default.
    pub const CLASSIC_1M: Self = Self::Classic { bitrate: 1_000_000 };
    /// CAN FD at 1 Mbit/s nominal, 5 Mbit/s data.
    pub const FD_1M_5M: Self = Self::Fd { nominal: 1_000_000, data: 5_000_000 };

    /// The bus in the protocol's budget terms (one formula for frame times).
    pub fn budget(self) -> budget::Bus {
        match self {
            Self::Classic { bitrate } => budget::Bus::ClassicCan { bitrate },
            Self::Fd { nominal, data } => budget::Bus::CanFd { nominal, data },
        }
    }

    /// Which messages nodes on this bus use.
    pub fn link(self) -> Link {
        self.budget().link()
    }

    /// The nominal bit rate, bit/s (at least 1).
    pub fn nominal_bitrate(self) -> u32 {
        match self {
            Self::Classic { bitrate } => bitrate.max(1),
            Self::Fd { nominal, .. } => nominal.max(1),
        }
    }

    fn bit_time(self) -> Duration {
        Duration::from_nanos(1_000_000_000 / u64::from(self.nominal_bitrate()))
    }

    fn frame_time(self, frame: &Frame) -> Duration {
        Duration::from_nanos(self.budget().frame_time_ns(frame.dlc()))
    }
}

/// Why a frame was not sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BusError {
    /// An FD frame on a classic CAN bus.
    #[error("CAN FD frame on a classic CAN bus")]
    FdOnClassicBus,
    /// The bus is off (a fault window): the frame was discarded.
    #[error("the bus is off")]
    BusOff,
    /// The bus no longer exists.
    #[error("the bus is closed")]
    Closed,
}

/// Traffic counters since the bus was created.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BusStats {
    /// Frames transmitted (dropped ones included, error frames not).
    pub frames: u64,
    /// Bus time used by frames and error frames.
    pub busy: Duration,
    /// Frames cut short by a bit error (and retransmitted).
    pub error_frames: u64,
    /// Frames lost at every receiver (the `drop` fault).
    pub dropped: u64,
    /// Frames discarded because the bus was off.
    pub bus_off: u64,
    /// Frames a port could not take because its receive queue was full.
    pub overruns: u64,
    /// Time since the bus was created.
    pub elapsed: Duration,
}

impl BusStats {
    /// The fraction of time the bus was busy, 0..=1.
    pub fn load(&self) -> f64 {
        if self.elapsed.is_zero() {
            0.0
        } else {
            self.busy.as_secs_f64() / self.elapsed.as_secs_f64()
        }
    }

    /// The traffic between `earlier` and these counters.
    pub fn since(&self, earlier: &BusStats) -> BusStats {
        BusStats {
            frames: self.frames - earlier.frames,
            busy: self.busy.saturating_sub(earlier.busy),
            error_frames: self.error_frames - earlier.error_frames,
            dropped: self.dropped - earlier.dropped,
            bus_off: self.bus_off - earlier.bus_off,
            overruns: self.overruns - earlier.overruns,
            elapsed: self.elapsed.saturating_sub(earlier.elapsed),
        }
    }
}

/// A received frame and when its last bit crossed the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Received {
    /// The frame.
    pub frame: Frame,
    /// The end of the frame on the bus's timeline.
    pub at: Instant,
}

/// A frame waiting in a port's queue.
#[derive(Debug)]
struct Pending {
    frame: Frame,
    queued_at: Instant,
    done: Option<oneshot::Sender<Result<(), BusError>>>,
}

impl Pending {
    fn finish(self, result: Result<(), BusError>) {
        if let Some(done) = self.done {
            // The sender may have stopped waiting.
            let _ = done.send(result);
        }
    }
}

/// One attachment to the bus.
#[derive(Debug)]
struct Port {
    /// Frames waiting to be sent, oldest first.
    queue: VecDeque<Pending>,
    /// Where received frames go (`None` once the port is gone).
    inbox: Option<mpsc::Sender<Received>>,
}

/// The frame occupying the bus.
#[derive(Debug)]
struct Transmission {
    port: usize,
    pending: Pending,
    start: Instant,
    end: Instant,
    fault: FrameFault,
}

/// The medium: queues, the frame on the wire, deliveries in flight.
#[derive(Debug)]
struct Medium {
    kind: CanKind,
    origin: Instant,
    ports: Vec<Port>,
    free_at: Instant,
    on_wire: Option<Transmission>,
    /// Frames on their way to the receivers (the `delay` fault), in time order.
    deliveries: VecDeque<(Instant, usize, Received)>,
    stats: BusStats,
    faults: BusFaultInjector,
    log: Option<CandumpLog>,
    closed: bool,
}

#[derive(Debug)]
struct Shared {
    medium: Mutex<Medium>,
    wake: Notify,
}

impl Shared {
    fn medium(&self) -> MutexGuard<'_, Medium> {
        self.medium.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// An in-process CAN bus. Dropping it closes every port.
#[derive(Debug)]
pub struct CanBus {
    shared: Arc<Shared>,
    kind: CanKind,
    origin: Instant,
    task: JoinHandle<()>,
}

impl CanBus {
    /// A fault-free bus without a log. Must be called within a tokio runtime.
    pub fn new(kind: CanKind) -> Self {
        Self::with(kind, &FaultSpec::default(), None)
    }

    /// A bus with the bus faults of `faults` (timed from now) and an optional log. Must be
    /// called within a tokio runtime.
    pub fn with(kind: CanKind, faults: &FaultSpec, log: Option<CandumpLog>) -> Self {
        let origin = Instant::now();
        let medium = Medium {
            kind,
            origin,
            ports: Vec::new(),
            free_at: origin,
            on_wire: None,
            deliveries: VecDeque::new(),
            stats: BusStats::default(),
            faults: BusFaultInjector::new(faults),
            log,
            closed: false,
        };
        let shared = Arc::new(Shared { medium: Mutex::new(medium), wake: Notify::new() });
        let task = tokio::spawn(run(Arc::clone(&shared)));
        Self { shared, kind, origin, task }
    }

    /// Attaches a new port (a controller on the bus).
    pub fn attach(&self) -> CanPort {
        let (tx, rx) = mpsc::channel(RX_QUEUE);
        let mut medium = self.shared.medium();
        let port = medium.ports.len();
        let sender = (!medium.closed).then_some(tx);
        medium.ports.push(Port { queue: VecDeque::new(), inbox: sender });
        CanPort {
            sender: CanSender { shared: Arc::clone(&self.shared), port, kind: self.kind },
            receiver: CanReceiver { rx },
        }
    }

    /// The bus's kind and speed.
    pub fn kind(&self) -> CanKind {
        self.kind
    }

    /// When the bus was created: the origin of fault times and of [`BusStats::elapsed`].
    pub fn origin(&self) -> Instant {
        self.origin
    }

    /// Traffic counters since the bus was created.
    pub fn stats(&self) -> BusStats {
        let medium = self.shared.medium();
        BusStats { elapsed: Instant::now().saturating_duration_since(self.origin), ..medium.stats }
    }

    /// The log's first write error so far, if any (see [`CandumpLog::failure`]).
    pub fn log_failure(&self) -> Option<String> {
        self.shared.medium().log.as_ref().and_then(CandumpLog::failure)
    }

    /// Writes out the log, if any; returns its first write error.
    pub fn flush_log(&self) -> std::io::Result<()> {
        self.shared.medium().log.as_mut().map_or(Ok(()), CandumpLog::flush)
    }
}

impl Drop for CanBus {
    fn drop(&mut self) {
        self.task.abort();
        let mut medium = self.shared.medium();
        medium.closed = true;
        if let Some(log) = medium.log.as_mut() {
            // Nobody is left to tell; the file gets what could be written.
            let _ = log.flush();
        }
        for port in &mut medium.ports {
            port.inbox = None;
            for pending in port.queue.drain(..) {
                pending.finish(Err(BusError::Closed));
            }
        }
    }
}

/// A port: sends and receives frames. [`split`](CanPort::split) it to send and receive from
/// different tasks.
#[derive(Debug)]
pub struct CanPort {
    sender: CanSender,
    receiver: CanReceiver,
}

impl CanPort {
    /// Sends a frame and waits until it has crossed the bus (or failed).
    pub async fn send(&self, frame: Frame) -> Result<(), BusError> {
        self.sender.send(frame).await
    }

    /// Queues a frame for sending without waiting.
    pub fn queue(&self, frame: Frame) -> Result<(), BusError> {
        self.sender.queue(frame)
    }

    /// The next frame from the bus; `None` once the bus is gone.
    pub async fn recv(&mut self) -> Option<Frame> {
        self.receiver.recv().await
    }

    /// The next frame from the bus with its time; `None` once the bus is gone.
    pub async fn recv_timed(&mut self) -> Option<Received> {
        self.receiver.recv_timed().await
    }

    /// A frame already received, if any.
    pub fn try_recv(&mut self) -> Option<Frame> {
        self.receiver.try_recv()
    }

    /// The sending and receiving halves.
    pub fn split(self) -> (CanSender, CanReceiver) {
        (self.sender, self.receiver)
    }
}

/// The sending half of a port; clones send through the same port queue.
#[derive(Clone, Debug)]
pub struct CanSender {
    shared: Arc<Shared>,
    port: usize,
    kind: CanKind,
}

impl CanSender {
    /// Sends a frame and waits until it has crossed the bus (or failed).
    pub async fn send(&self, frame: Frame) -> Result<(), BusError> {
        let (done, result) = oneshot::channel();
        self.enqueue(frame, Some(done))?;
        result.await.unwrap_or(Err(BusError::Closed))
    }

    /// Queues a frame for sending without waiting.
    pub fn queue(&self, frame: Frame) -> Result<(), BusError> {
        self.enqueue(frame, None)
    }

    fn enqueue(
        &self,
        frame: Frame,
        done: Option<oneshot::Sender<Result<(), BusError>>>,
    ) -> Result<(), BusError> {
        if frame.is_fd() && matches!(self.kind, CanKind::Classic { .. }) {
            return Err(BusError::FdOnClassicBus);
        }
        let mut medium = self.shared.medium();
        if medium.closed {
            return Err(BusError::Closed);
        }
        let queued_at = Instant::now();
        if let Some(port) = medium.ports.get_mut(self.port) {
            port.queue.push_back(Pending { frame, queued_at, done });
        }
        drop(medium);
        self.shared.wake.notify_one();
        Ok(())
    }
}

/// The receiving half of a port.
#[derive(Debug)]
pub struct CanReceiver {
    rx: mpsc::Receiver<Received>,
}

impl CanReceiver {
    /// The next frame from the bus; `None` once the bus is gone.
    pub async fn recv(&mut self) -> Option<Frame> {
        self.rx.recv().await.map(|r| r.frame)
    }

    /// The next frame from the bus with its time; `None` once the bus is gone.
    pub async fn recv_timed(&mut self) -> Option<Received> {
        self.rx.recv().await
    }

    /// A frame already received, if any.
    pub fn try_recv(&mut self) -> Option<Frame> {
        self.rx.try_recv().ok().map(|r| r.frame)
    }
}

/// The bus task: moves the medium forward whenever something is due.
async fn run(shared: Arc<Shared>) {
    loop {
        let next = shared.medium().advance(Instant::now());
        match next {
            Some(at) => tokio::select! {
                () = shared.wake.notified() => {}
                () = sleep_until(at) => {}
            },
            None => shared.wake.notified().await,
        }
    }
}

impl Medium {
    /// Plays the bus up to `now`; returns when something is next due (if anything is).
    fn advance(&mut self, now: Instant) -> Option<Instant> {
        loop {
            // With a constant delay, deliveries are in time order and come after those of
            // the frame on the wire.
            while self.deliveries.front().is_some_and(|(at, ..)| *at <= now) {
                if let Some((at, sender, received)) = self.deliveries.pop_front() {
                    self.deliver(at, sender, received);
                }
            }
            if let Some(wire) = &self.on_wire {
                if wire.end > now {
                    return Some(self.next_delivery().map_or(wire.end, |d| d.min(wire.end)));
                }
                if let Some(wire) = self.on_wire.take() {
                    self.finish(wire);
                }
                continue;
            }
            let bit = self.kind.bit_time();
            let earliest =
                self.ports.iter().filter_map(|p| p.queue.front()).map(|p| p.queued_at + bit).min();
            let Some(earliest) = earliest else { return self.next_delivery() };
            let start = earliest.max(self.free_at);
            if start > now {
                return Some(self.next_delivery().map_or(start, |d| d.min(start)));
            }
            if self.faults.is_bus_off(start.saturating_duration_since(self.origin)) {
                self.fail_all(BusError::BusOff);
                self.free_at = start;
                continue;
            }
            self.arbitrate(start, bit);
        }
    }

    fn next_delivery(&self) -> Option<Instant> {
        self.deliveries.front().map(|(at, ..)| *at)
    }

    /// Puts on the wire, at `start`, the lowest-id frame of those ready by then.
    fn arbitrate(&mut self, start: Instant, bit: Duration) {
        let winner = self
            .ports
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.queue.front().map(|f| (i, f)))
            .filter(|(_, f)| f.queued_at + bit <= start)
            .min_by_key(|(i, f)| (f.frame.standard_id().as_raw(), *i))
            .map(|(i, _)| i);
        let Some(port) = winner else { return };
        let Some(pending) = self.ports.get_mut(port).and_then(|p| p.queue.pop_front()) else {
            return;
        };
        let frame_time = self.kind.frame_time(&pending.frame);
        let bits = (frame_time.as_nanos() / bit.as_nanos().max(1)) as usize;
        let fault = self.faults.draw(bits);
        let time = match fault {
            FrameFault::Corrupted { bit: at } => {
                bit * (at as u32 + 1) + bit * ERROR_FRAME_BITS as u32
            }
            FrameFault::None | FrameFault::Dropped => frame_time,
        };
        self.on_wire = Some(Transmission { port, pending, start, end: start + time, fault });
    }

    /// The frame on the wire is over: count it, retransmit it or hand it to the receivers.
    fn finish(&mut self, wire: Transmission) {
        let Transmission { port, pending, start, end, fault } = wire;
        self.free_at = end;
        match fault {
            FrameFault::Corrupted { .. } => {
                self.stats.error_frames += 1;
                self.stats.busy += end.saturating_duration_since(start);
                if let Some(log) = self.log.as_mut() {
                    log.error_frame(end);
                }
                // Automatic retransmission: back to the head of its queue.
                if let Some(p) = self.ports.get_mut(port) {
                    p.queue.push_front(pending);
                }
            }
            FrameFault::Dropped | FrameFault::None => {
                self.stats.frames += 1;
                self.stats.busy += self.kind.frame_time(&pending.frame);
                let received = Received { frame: pending.frame, at: end };
                pending.finish(Ok(()));
                if fault == FrameFault::Dropped {
                    self.stats.dropped += 1;
                } else {
                    self.deliveries.push_back((end + self.faults.delay(), port, received));
                }
            }
        }
    }

    /// Hands a frame to every port but its sender, and to the log.
    fn deliver(&mut self, at: Instant, sender: usize, received: Received) {
        if let Some(log) = self.log.as_mut() {
            log.frame(at, &received.frame);
        }
        let received = Received { at, ..received };
        for (i, port) in self.ports.iter_mut().enumerate() {
            let Some(inbox) = &port.inbox else { continue };
            if i == sender {
                continue;
            }
            match inbox.try_send(received) {
                Ok(()) => {}
                Err(mpsc::error::TrySendError::Full(_)) => self.stats.overruns += 1,
                Err(mpsc::error::TrySendError::Closed(_)) => port.inbox = None,
            }
        }
    }

    /// Discards every queued frame (bus-off).
    fn fail_all(&mut self, error: BusError) {
        for port in &mut self.ports {
            for pending in port.queue.drain(..) {
                self.stats.bus_off += 1;
                pending.finish(Err(error));
            }
        }
    }
}
