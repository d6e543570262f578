//! Simulations that stand in for hardware in tests, CI and the demo.
//!
//! Two jobs that share nothing (`tests/scripts/module_dag.py` checks that neither imports the
//! other): synthetic customers, and the form simulator.
//!
//! - [`capture`]: synthetic body scans with known ground truth, and scanner artifacts.
//! - [`node`]: the simulated node, the node side of `firmware-protocol` as a pure state
//!   machine.
//! - [`fault`]: fault injection per run (bus, node, actuator) from one spec string.
//! - [`bus`]: simulated buses: in-process CAN, serial and slcan over pseudo-terminals,
//!   candump logs.
//! - [`robot`]: the simulated robotic form: a form's nodes running on a bus, with faults and
//!   ground truth.
//! - [`serve`]: serving a simulated form on a pseudo-terminal (`dressform sim`).

pub mod bus;
pub mod capture;
pub mod fault;
pub mod node;
pub mod robot;
pub mod serve;
