//! No sequence of inputs makes the host send a target outside an actuator's stroke: a
//! property test drives the controller's public API on the simulated form (paused clock) with
//! arbitrary set-points (in and out of the stroke, NaN, infinities), forms with arbitrary
//! strokes, `--clamp` on or off, slower moves, lossy buses and node reboots (which make the
//! host retry and resume), and checks every packet the host's transport sends.

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use dressform::form::controller::transport::sim::SimBus;
use dressform::form::controller::{DriveOptions, Gate, Transport, TransportError, drive};
use dressform::form::setpoints::SetPoints;
use firmware_protocol::{Address, Link, Message, Packet};
use form_description::{FormDescription, reference};
use form_sim::bus::can::{CanBus, CanKind};
use form_sim::fault::FaultSpec;
use form_sim::robot::{SimOptions, SimulatedForm};
use proptest::prelude::*;

/// The simulated bus, keeping a copy of everything the host sends.
struct Recording {
    inner: SimBus,
    sent: Arc<Mutex<Vec<Packet>>>,
}

impl Transport for Recording {
    fn link(&self) -> Link {
        self.inner.link()
    }

    fn device(&self) -> String {
        self.inner.device()
    }

    fn gate(&self) -> &Gate {
        self.inner.gate()
    }

    async fn send(&mut self, packet: Packet) -> Result<(), TransportError> {
        self.sent.lock().unwrap().push(packet);
        self.inner.send(packet).await
    }

    async fn recv(&mut self) -> Result<Packet, TransportError> {
        self.inner.recv().await
    }
}

/// Every target slot of every packet lies within its actuator's stroke in `form`, and names
/// an actuator the node has.
fn check_targets(form: &FormDescription, sent: &[Packet]) -> Result<usize, String> {
    let mut slots = 0;
    for packet in sent {
        let (Address::Node(node), positions): (_, Vec<(usize, _)>) = (match packet.message {
            Message::Targets(four) => (
                packet.address,
                four.positions
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (four.half.first() + i, *p))
                    .collect(),
            ),
            Message::AllTargets(all) => {
                (packet.address, all.positions.iter().copied().enumerate().collect())
            }
            _ => continue,
        }) else {
            return Err(format!("targets broadcast: {packet:?}"));
        };
        for (index, position) in positions {
            let Some(position) = position else { continue };
            slots += 1;
            let spec = form
                .actuators_of(node)
                .into_iter()
                .find(|a| usize::from(a.channel) == index)
                .ok_or_else(|| {
                    format!("node {} has no actuator {index}: {packet:?}", node.get())
                })?;
            if position > spec.stroke() {
                return Err(format!("{}: {position:?} beyond stroke {:?}", spec.id, spec.stroke()));
            }
        }
    }
    Ok(slots)
}

fn position() -> impl Strategy<Value = f64> {
    prop_oneof![
        40 => -5.0..70.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(-0.0),
        1 => Just(1e300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn the_host_never_sends_a_target_outside_the_stroke(
        picks in proptest::collection::btree_map(0usize..72, position(), 0..20),
        strokes in proptest::collection::vec(0.3..1.0f64, 8),
        clamp in proptest::bool::weighted(0.8),
        slower in 1.0..3.0f64,
        lossy in any::<bool>(),
        reboot_at_ms in proptest::option::of(1000u64..4000),
        seed in 0u64..1000,
        fd in any::<bool>(),
    ) {
        // The form, with each node's strokes scaled (the thighs, nodes 7 and 8, alike: they
        // mirror each other; the lifts, node 9, too).
        let mut spec = reference().into_spec();
        for a in &mut spec.actuators {
            let factor = strokes[usize::from(a.node.min(7)) - 1];
            a.stroke_mm = (a.stroke_mm * factor * 100.0).round() / 100.0;
        }
        for lift in &mut spec.lifts {
            lift.stroke_mm = (lift.stroke_mm * strokes[7] * 100.0).round() / 100.0;
        }
        let form = FormDescription::try_from(spec).unwrap();
        let ids: Vec<String> = form.axes().map(|a| a.id.to_string()).collect();
        let positions: BTreeMap<String, f64> =
            picks.iter().map(|(&i, &mm)| (ids[i].clone(), mm)).collect();
        let setpoints = SetPoints::new(form.name.clone(), positions);
        let mut faults = format!("seed={seed}");
        if lossy {
            faults.push_str(",drop=0.05,corrupt=0.01");
        }
        if let Some(ms) = reboot_at_ms {
            faults.push_str(&format!(",node2:reboot@{ms}ms"));
        }
        let faults: FaultSpec = faults.parse().unwrap();
        let kind = if fd { CanKind::FD_1M_5M } else { CanKind::CLASSIC_1M };
        let options = DriveOptions { clamp, slower, ..DriveOptions::default() };
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .start_paused(true)
            .build()
            .unwrap();
        let sent = Arc::new(Mutex::new(Vec::new()));
        let outcome = runtime.block_on(async {
            let bus = CanBus::with(kind, &faults, None);
            let _simulated = SimulatedForm::on_can(&form, &bus, &faults, &SimOptions::default()).unwrap();
            let transport = Recording { inner: SimBus::attach(&bus), sent: Arc::clone(&sent) };
            drive(transport, &form, &setpoints, &options, |_| {}).await
        });
        let sent = sent.lock().unwrap();
        let slots = check_targets(&form, &sent).map_err(TestCaseError::fail)?;
        // A refused file sends nothing at all.
        let out_of_stroke = setpoints.positions_mm.iter().any(|(id, &mm)| {
            let stroke = form.axis(id).unwrap().stroke_mm;
            !(0.0..=stroke).contains(&mm)
        });
        if out_of_stroke && !clamp {
            prop_assert!(sent.is_empty(), "{outcome:?}");
        } else if outcome.is_ok() {
            prop_assert!(slots >= setpoints.positions_mm.len());
        }
    }
}
