//! The controller on real pseudo-terminals, as on hardware: the simulated reference form is
//! served by `sim::serve` (as `dressform sim` does) with the serial mapping or behind an slcan
//! adapter, and the host opens the pty's path with `serialport` (real time, a few seconds).

use std::collections::BTreeMap;
use std::path::Path;

use dressform::controller::transport::serial::SerialLine;
use dressform::controller::transport::slcan::Slcan;
use dressform::controller::{Connection, DriveOptions, LinkSpec, Transport, drive, status};
use dressform::setpoints::SetPoints;
use firmware_protocol::drive::Faults;
use sim::form::reference;
use sim::serve::{ServeConfig, Server, Transport as Served, serve};
use tokio::runtime::Runtime;

/// The reference form served on a pty of `transport`, on a runtime of its own.
pub(crate) fn start(transport: Served) -> (Runtime, Server) {
    let runtime =
        tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
    let server = {
        let _context = runtime.enter();
        serve(ServeConfig::new(reference(), transport)).unwrap()
    };
    (runtime, server)
}

/// A few actuators on several nodes, short moves.
fn setpoints() -> SetPoints {
    let positions: BTreeMap<String, f64> = [
        ("neck-front", 3.0),
        ("chest-l1", 4.5),
        ("chest-r1", 4.5),
        ("waist-back", 3.25),
        ("thigh-r-inner", 2.0),
    ]
    .into_iter()
    .map(|(id, mm)| (id.to_string(), mm))
    .collect();
    SetPoints::new("reference", positions)
}

fn drive_over<T: Transport>(runtime: &Runtime, server: &Server, transport: T) {
    let form = reference();
    let setpoints = setpoints();
    let report = runtime
        .block_on(drive(transport, &form, &setpoints, &DriveOptions::default(), |_| {}))
        .unwrap();
    assert!(report.converged(), "{report:?}");
    let truth = server.form().state();
    for (id, &mm) in &setpoints.positions_mm {
        let real = truth.actuator(id).unwrap().state.position_mm;
        assert!((real - mm).abs() <= 0.1, "{id}: {real} vs {mm}");
    }
}

#[test]
fn drives_the_form_over_a_serial_pty() {
    let (runtime, server) = start(Served::SerialPty);
    let line = SerialLine::open(server.device_path()).unwrap();
    drive_over(&runtime, &server, line);
    // Status over the same pty afterwards: every node identified, Disabled, positions known.
    let connection = Connection::open(&LinkSpec::Serial(server.device_path().into())).unwrap();
    let form = reference();
    let nodes =
        runtime.block_on(status(connection, &form, std::time::Duration::from_millis(200))).unwrap();
    assert_eq!(nodes.len(), 8);
    for node in &nodes {
        assert!(node.identified && node.problems.is_empty(), "{node:?}");
        assert_eq!(node.state.as_deref(), Some("Disabled"), "{node:?}");
    }
    let chest = nodes.iter().find(|n| n.node == 2).unwrap();
    let l1 = chest.positions_mm.iter().find(|(id, _)| id == "chest-l1").unwrap().1.unwrap();
    assert!((l1 - 4.5).abs() <= 0.1, "{l1}");
}

#[test]
fn drives_the_form_over_slcan_on_a_pty() {
    let (runtime, server) = start(Served::SlcanPty);
    let slcan = Slcan::open(server.device_path()).unwrap();
    drive_over(&runtime, &server, slcan);
}

#[test]
fn an_emergency_stop_over_the_serial_pty_reaches_every_node() {
    let (_runtime, server) = start(Served::SerialPty);
    let connection = Connection::open(&LinkSpec::Serial(server.device_path().into())).unwrap();
    dressform::controller::emergency_stop(&connection).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(100));
    for node in server.form().state().nodes {
        assert!(node.faults.contains(Faults::EMERGENCY_STOP), "node {}", node.node.get());
    }
}

#[test]
fn a_missing_device_is_a_clear_error() {
    let error = SerialLine::open(Path::new("/dev/does-not-exist")).unwrap_err();
    assert!(error.to_string().contains("/dev/does-not-exist"), "{error}");
}
