//! The simulated robotic form: the form's controller boards ("nodes") speaking
//! `firmware-protocol` on simulated buses, with the protocol's timing and injectable faults.
//! It stands in for the robot in tests, CI and the demo.
//!
//! - [`node`]: the simulated node, the node side of `firmware-protocol` as a pure state
//!   machine.
//! - [`fault`]: fault injection per run (bus, node, actuator) from one spec string.
//! - [`garment`]: a garment on the form: its description and the load it puts on the panels.
//! - [`bus`]: simulated buses: in-process CAN, serial and slcan over pseudo-terminals,
//!   candump logs.
//! - [`robot`]: the simulated robotic form: a form's nodes running on a bus, with faults and
//!   ground truth.
//! - [`serve`]: serving a simulated form on a pseudo-terminal (`dressform sim`).

pub mod bus;
pub mod fault;
pub mod garment;
pub mod node;
pub mod robot;
pub mod serve;
