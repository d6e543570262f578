//! The integration tests of this crate, as one test binary (each module was its own binary;
//! one binary links the crate once).

#[path = "../../../tests/common/skip.rs"]
mod skip;
mod test_host;

mod bus_budget;
mod can_bus;
mod fault_injection;
mod form_on_can;
mod garment_on_form;
mod node_state_machine;
mod serial_pty;
mod slcan_pty;
mod slcan_python_can;
