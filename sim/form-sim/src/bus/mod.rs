//! Simulated buses between a host and the form's nodes.
//!
//! - [`can`]: an in-process CAN bus (classic or FD) with arbitration by identifier, frame
//!   times from the bit rate, bus-load counters and faults; deterministic under tokio's
//!   paused clock. Hosts attach [`CanPort`](can::CanPort)s.
//! - [`pty`]: a pseudo-terminal pair; hosts open its slave path (`/dev/pts/N`) like a USB
//!   adapter.
//! - [`serial`]: the protocol's serial mapping on a pty (the form answers polls).
//! - [`slcan`]: an slcan (Lawicel ASCII) USB-CAN adapter on a pty, bridged to a CAN bus.
//! - [`candump`]: the candump log of the traffic.

pub mod can;
pub mod candump;
pub mod pty;
pub mod serial;
pub mod slcan;
