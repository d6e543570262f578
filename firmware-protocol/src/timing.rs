//! Periods and timeouts both sides keep (defaults; the node ones are parameters).
//!
//! * The host sends `HostHeartbeat` every [`HOST_HEARTBEAT_PERIOD_MS`]. A node whose last
//!   host heartbeat is older than its watchdog timeout ([`WATCHDOG_TIMEOUT_MS`], three
//!   periods) while Enabled or Homing stops its actuators and latches `HOST_TIMEOUT`
//!   (the CANopen consumer heartbeat, the ODrive axis watchdog).
//! * On CAN, a node sends `Heartbeat` every [`HEARTBEAT_PERIOD_MS`] and its positions every
//!   [`FEEDBACK_PERIOD_MS`], each time followed by its forces if its host announced protocol
//!   1.1 or later; the host declares a node lost after [`NODE_LOST_AFTER_MS`]
//!   without its heartbeat.
//! * On a serial line nodes speak only when asked: the host polls each node with an
//!   addressed `HostHeartbeat` every [`FEEDBACK_PERIOD_MS`] (which also feeds its watchdog);
//!   a node answers within [`SERIAL_REPLY_WITHIN_MS`], and is lost after
//!   [`NODE_LOST_AFTER_MS`] without an answer.
//! * A node answers a request (`Ack`, `ParamValue`, `Identity`) within
//!   [`REPLY_WITHIN_MS`]; the host then retries with the same sequence number (serial), at
//!   most [`RETRIES`] times.

/// Host heartbeat period (ms).
pub const HOST_HEARTBEAT_PERIOD_MS: u16 = 100;
/// Node watchdog timeout (ms): three host heartbeat periods.
pub const WATCHDOG_TIMEOUT_MS: u16 = 300;
/// Node heartbeat period on CAN (ms).
pub const HEARTBEAT_PERIOD_MS: u16 = 100;
/// Position (and, to a 1.1 host, force) feedback period on CAN, and the poll period on
/// serial (ms).
pub const FEEDBACK_PERIOD_MS: u16 = 20;
/// The host declares a node lost after this long without a heartbeat (ms).
pub const NODE_LOST_AFTER_MS: u16 = 300;
/// Longest time a node takes to answer a request (ms).
pub const REPLY_WITHIN_MS: u16 = 10;
/// Longest time from the end of a poll to the start of a node's answer on serial (ms).
pub const SERIAL_REPLY_WITHIN_MS: u16 = 2;
/// How often the host retries an unanswered request.
pub const RETRIES: u8 = 2;
