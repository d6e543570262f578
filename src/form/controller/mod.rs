//! The host controller: drives the robotic form over serial, CAN, slcan or the in-process
//! simulated bus.
//!
//! [`drive()`] runs one shape change: check the set-points against the form description
//! (nothing outside a stroke, see [`crate::form::safety`]), discover every node and check it against the
//! description ([`session`]), enable and home, one synchronised move with live progress and
//! per-actuator report ([`motion`]), then disable (the drives hold the panels).
//! [`drive_after`] does the same with set-points computed while the form is held.
//!
//! | module | what it holds |
//! |---|---|
//! | [`transport`] | the [`Transport`] trait; serial, slcan, SocketCAN and simulated links; the [`Gate`] every packet goes through, and the e-stop on it from any thread (`transport::gate`) |
//! | [`claim`] | the form claimed for a whole command: e-stops latched at its start recorded, the link kept alive while it computes, no later e-stop cleared |
//! | [`control`] | the local control endpoint: `dressform estop` reaching the link's owner; [`emergency_stop`] on a link of this process |
//! | [`session`] | discovery, liveness (heartbeats, polls, stalls), fault handling, enable/home, reboots |
//! | [`drive`](mod@drive) | a move of the whole form: options, report, errors; the drive after a computation ([`drive_after`]) |
//! | [`plan`](mod@plan) | a move's plan: the set-points checked against the strokes |
//! | [`motion`] | staging, the common SYNC duration, watching feedback, the report |
//! | [`status`](mod@status) | `dressform status`: every node's state, unchanged |
//! | [`reset`](mod@reset) | `dressform reset`: latched faults cleared |
//! | [`faults`] | states, faults, events and refusals in words; which faults the host clears |
//! | [`forces`] | what the form feels at rest (protocol 1.1): every actuator's force, averaged |
//! | [`open`] | opening the link a [`LinkSpec`] names, starting the simulated form for `--sim` |
//! | [`simulated`] | the whole thing on the in-process simulated form |
//!
//! Safety rules, all enforced here: targets come only from [`SafeTarget`]s built against the
//! description's strokes (checked against what every node reports); the SYNC duration is
//! never shorter than the shortest feasible for every actuator; a fault (during homing or a
//! move) broadcasts `Halt` and disables every node; a lost node, a stalled link, a reboot that
//! cannot be resumed or a failed link end the move with an error; an e-stop (another terminal, a signal) latches the link's [`Gate`]
//! and broadcasts `EmergencyStop` without waiting for the session; a hardware fault is never
//! cleared without the caller's say-so.

pub mod claim;
pub mod control;
pub mod drive;
pub mod faults;
pub mod forces;
pub mod motion;
pub mod open;
pub mod plan;
pub mod reset;
pub mod session;
#[cfg(feature = "simulator")]
pub mod simulated;
// Without the simulator: its types, and the refusal to start one.
#[cfg(not(feature = "simulator"))]
#[path = "no_simulator.rs"]
pub mod simulated;
pub mod status;
pub mod transport;

pub use crate::form::safety::SafeTarget;
pub use claim::Claim;
pub use control::emergency_stop;
pub use drive::{
    ComputeThreadError, DEFAULT_HOMING_TIMEOUT, DEFAULT_SETTLE, DEFAULT_TOLERANCE_MM,
    DriveAfterError, DriveError, DriveOptions, DriveReport, drive, drive_after,
};
pub use faults::{fault_names, state_name};
pub use forces::{DEFAULT_FORCE_WINDOW, ForceSample};
pub use motion::{ActuatorReport, MoveError, NodeProgress, PlannedTarget, Progress};
pub use plan::{Clamped, plan};
pub use reset::{ResetReport, reset};
pub use session::{Cleared, NodeProblem, Session, SessionError};
pub use status::{NodeReport, status};
pub use transport::{Connection, Gate, LinkSpec, StopCause, Transport, TransportError};
