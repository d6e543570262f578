//! The simulated robotic form: the nodes of a [`FormDescription`] running on a bus, with
//! the faults of a run, and the ground truth a test can check the host against.
//!
//! ```no_run
//! # async fn demo() -> Result<(), Box<dyn std::error::Error>> {
//! use form_sim::bus::can::{CanBus, CanKind};
//! use form_sim::fault::FaultSpec;
//! use form_sim::robot::{SimOptions, SimulatedForm};
//!
//! let bus = CanBus::new(CanKind::CLASSIC_1M);
//! let form = SimulatedForm::on_can(&form_description::reference(), &bus, &FaultSpec::default(),
//!                                  &SimOptions::default())?;
//! let mut host = bus.attach();          // the host controller's port
//! let frame = host.recv().await;        // boot-up heartbeats, feedback, ...
//! let truth = form.state();             // where every panel really is
//! # Ok(()) }
//! ```
//!
//! On CAN every node is its own task with its own port; on a serial line (see
//! [`crate::serve`]) one task hosts all nodes behind the line. Every node is ticked every
//! [`SimOptions::tick`]; a tick is when events are noticed (watchdog, home switch, following
//! error) and cyclic frames are due, so they are at most one tick late. Dropping a
//! [`SimulatedForm`] stops its nodes.

mod node_sim;
mod runners;
pub mod world;

use std::sync::{Arc, Mutex};

use firmware_protocol::drive::{DriveState, Faults};
use firmware_protocol::version::FirmwareVersion;
use firmware_protocol::{Actuator, Force, Link, NodeId, PROTOCOL_VERSION, ProtocolVersion};
use tokio::sync::oneshot;
use tokio::task::JoinHandle;
use tokio::time::{Duration, Instant};

use crate::bus::can::CanBus;
use crate::bus::serial::SerialLine;
use crate::fault::{FaultSpec, FaultSpecError, NodeSchedule};
use crate::garment::GarmentSpec;
use crate::node::{ActuatorConfig, ActuatorFault, ActuatorState, Node, NodeConfig};
use form_description::FormDescription;
use node_sim::NodeSim;
use runners::{SharedCanary, SharedNode, Stalls, lock};
use world::SharedGarment;

/// How the simulated form behaves beyond its description.
#[derive(Clone, Debug, PartialEq)]
pub struct SimOptions {
    /// How often nodes are ticked (default 1 ms).
    pub tick: Duration,
    /// Standard deviation of position noise in feedback, mm (default 0.01 mm, clipped at
    /// 4σ).
    pub noise_mm: f64,
    /// Seed of the noise; node `n` uses `seed + n` (default 0).
    pub seed: u64,
    /// Where every panel physically is at power-on, mm from home (default 2 mm; homing
    /// finds it).
    pub start_position_mm: f64,
    /// The firmware version nodes report (default 1.0.0).
    pub firmware: FirmwareVersion,
    /// The protocol version nodes speak (default this crate's, 1.1; 1.0 nodes measure no
    /// force).
    pub protocol: ProtocolVersion,
    /// The rated force of every actuator, N: the default and highest force limit (default
    /// [`RATED_FORCE_N`]).
    pub rated_force_n: f64,
    /// Standard deviation of the force sensors' noise, N (default [`FORCE_NOISE_N`], clipped
    /// at 4σ).
    pub force_noise_n: f64,
    /// The garment the form wears from power-on (default none; see
    /// [`SimulatedForm::dress`]).
    pub garment: Option<GarmentSpec>,
}

/// The simulated actuators' rated force, N: twice the description's default limit
/// (`form_description::DEFAULT_FORCE_LIMIT_N`), so the limit the host writes is what stops
/// them.
pub const RATED_FORCE_N: f64 = 100.0;

/// The simulated force sensors' noise, N (one standard deviation): 0.1% of the rated force, a
/// deliberately pessimistic figure (a C3-class load cell, OIML R 60's 3000 divisions, errs
/// by a few hundredths of a percent of its capacity), so the fit test's averaging and contact
/// rule are exercised.
pub const FORCE_NOISE_N: f64 = 0.1;

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            tick: Duration::from_millis(1),
            noise_mm: 0.01,
            seed: 0,
            start_position_mm: 2.0,
            firmware: FirmwareVersion { major: 1, minor: 0, patch: 0 },
            protocol: PROTOCOL_VERSION,
            rated_force_n: RATED_FORCE_N,
            force_noise_n: FORCE_NOISE_N,
            garment: None,
        }
    }
}

/// Why a simulated form could not start.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The fault spec names what the form lacks.
    #[error(transparent)]
    Faults(#[from] FaultSpecError),
}

/// The truth about a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeTruth {
    /// Its address.
    pub node: NodeId,
    /// Its drive state.
    pub state: DriveState,
    /// Its latched faults.
    pub faults: Faults,
    /// Cut off the bus by a `silent` fault.
    pub silent: bool,
}

/// The truth about an actuator.
#[derive(Clone, Debug, PartialEq)]
pub struct ActuatorTruth {
    /// Its id in the form.
    pub id: String,
    /// Its node.
    pub node: NodeId,
    /// Its index on the node.
    pub actuator: Actuator,
    /// Position, velocity and status.
    pub state: ActuatorState,
}

/// A snapshot of the whole form at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct FormState {
    /// When.
    pub at: Instant,
    /// Every node, in description order.
    pub nodes: Vec<NodeTruth>,
    /// Every actuator, by node and index.
    pub actuators: Vec<ActuatorTruth>,
}

impl FormState {
    /// The actuator with this id.
    pub fn actuator(&self, id: &str) -> Option<&ActuatorTruth> {
        self.actuators.iter().find(|a| a.id == id)
    }

    /// The node with this address.
    pub fn node(&self, node: NodeId) -> Option<&NodeTruth> {
        self.nodes.iter().find(|n| n.node == node)
    }
}

/// A running simulated form.
#[derive(Debug)]
pub struct SimulatedForm {
    description: FormDescription,
    nodes: Vec<SharedNode>,
    garment: SharedGarment,
    tasks: Vec<JoinHandle<()>>,
}

impl SimulatedForm {
    /// Powers the form's nodes on, each on its own port of `bus` (classic or FD, as the bus
    /// is), with `faults` timed from the bus's creation. Must be called within a tokio
    /// runtime.
    pub fn on_can(
        description: &FormDescription,
        bus: &CanBus,
        faults: &FaultSpec,
        options: &SimOptions,
    ) -> Result<Self, SimError> {
        Self::on_can_behind(description, bus, faults, options, None)
    }

    /// [`SimulatedForm::on_can`] with the host behind a pseudo-terminal whose stalls
    /// `canary` measures (see `runners`).
    pub(crate) fn on_can_behind(
        description: &FormDescription,
        bus: &CanBus,
        faults: &FaultSpec,
        options: &SimOptions,
        canary: Option<SharedCanary>,
    ) -> Result<Self, SimError> {
        let nodes = power_on(description, bus.kind().link(), faults, options, bus.origin())?;
        let start = Instant::now();
        let garment: SharedGarment = Arc::new(Mutex::new(options.garment.clone()));
        let world = world::run(description.clone(), nodes.clone(), garment.clone(), options.tick);
        let tasks = nodes
            .iter()
            .map(|node| {
                let stalls = Stalls::new(canary.clone());
                let task = runners::node_on_can(
                    Arc::clone(node),
                    bus.attach(),
                    options.tick,
                    start,
                    stalls,
                );
                tokio::spawn(task)
            })
            .chain([tokio::spawn(world)])
            .collect();
        Ok(Self { description: description.clone(), nodes, garment, tasks })
    }

    /// Powers the form's nodes on behind a serial line; the caller runs the line with
    /// [`SimulatedForm::serve_serial`].
    pub(crate) fn on_serial(
        description: &FormDescription,
        faults: &FaultSpec,
        options: &SimOptions,
    ) -> Result<Self, SimError> {
        let nodes = power_on(description, Link::Serial, faults, options, Instant::now())?;
        let garment: SharedGarment = Arc::new(Mutex::new(options.garment.clone()));
        let world = world::run(description.clone(), nodes.clone(), garment.clone(), options.tick);
        let tasks = vec![tokio::spawn(world)];
        Ok(Self { description: description.clone(), nodes, garment, tasks })
    }

    /// Answers the host on `line` until `stop` (or an I/O error), then writes out the line's
    /// log. Resolves to the line's result and the log's. `canary` measures the stalls of the
    /// line's pseudo-terminal (see `runners`).
    pub(crate) fn serve_serial(
        &self,
        mut line: SerialLine,
        tick: Duration,
        canary: SharedCanary,
        stop: oneshot::Receiver<()>,
    ) -> impl Future<Output = (std::io::Result<()>, std::io::Result<()>)> + Send + 'static {
        let nodes = self.nodes.clone();
        let stalls = Stalls::new(Some(canary));
        async move {
            let result = tokio::select! {
                result = runners::nodes_on_serial(&nodes, &mut line, tick, stalls) => result,
                _ = stop => Ok(()),
            };
            (result, line.flush_log())
        }
    }

    /// Breaks an actuator now (see [`ActuatorFault`]); `false` if the form has no such
    /// actuator. Faults at planned times go in the run's [`FaultSpec`].
    pub fn inject(&self, actuator: &str, fault: ActuatorFault) -> bool {
        let Some((node, index)) = self.description.locate(actuator) else { return false };
        let Some(shared) = self.node(node) else { return false };
        lock(shared).node.inject(Instant::now(), index, fault);
        true
    }

    /// Repairs an actuator now (a technician freed a jam or replaced an encoder; the latched
    /// fault stays until the host's FaultReset); `false` if the form has no such actuator.
    pub fn repair(&self, actuator: &str) -> bool {
        let Some((node, index)) = self.description.locate(actuator) else { return false };
        let Some(shared) = self.node(node) else { return false };
        lock(shared).node.repair(Instant::now(), index);
        true
    }

    /// Puts `garment` on the form now (replacing what it wore), or takes it off (`None`).
    pub fn dress(&self, garment: Option<GarmentSpec>) {
        *lock(&self.garment) = garment;
    }

    /// Reboots a node's controller now; `false` if the form has no such node.
    pub fn reboot(&self, node: NodeId) -> bool {
        let Some(shared) = self.node(node) else { return false };
        lock(shared).node.reboot(Instant::now());
        true
    }

    fn node(&self, node: NodeId) -> Option<&SharedNode> {
        self.nodes.iter().find(|shared| lock(shared).node.id() == node)
    }

    /// The description the form was built from.
    pub fn description(&self) -> &FormDescription {
        &self.description
    }

    /// The truth about every node and actuator now.
    pub fn state(&self) -> FormState {
        let now = Instant::now();
        let mut state = FormState { at: now, nodes: Vec::new(), actuators: Vec::new() };
        for shared in &self.nodes {
            let sim = lock(shared);
            let node = sim.node.id();
            state.nodes.push(NodeTruth {
                node,
                state: sim.node.state(),
                faults: sim.node.faults(),
                silent: sim.is_silent(now),
            });
            for (actuator, truth) in Actuator::all().zip(sim.node.actuator_states(now)) {
                let id = self.description.actuator_at(node, actuator).map(|a| a.id.to_string());
                state.actuators.push(ActuatorTruth {
                    id: id.unwrap_or_default(),
                    node,
                    actuator,
                    state: truth,
                });
            }
        }
        state
    }
}

impl Drop for SimulatedForm {
    fn drop(&mut self) {
        for task in &self.tasks {
            task.abort();
        }
    }
}

/// The configuration of one node of `description` on `link`.
pub fn node_config(
    description: &FormDescription,
    node: NodeId,
    link: Link,
    options: &SimOptions,
) -> NodeConfig {
    let actuators = description
        .actuators_of(node)
        .into_iter()
        .map(|a| ActuatorConfig {
            stroke: a.stroke(),
            max_speed: a.max_speed().hundredths_mm_s(),
            max_accel: a.max_accel().tenths_mm_s2(),
            start_mm: options.start_position_mm.max(0.0).min(a.stroke_mm),
            rated_force: Force::from_n(options.rated_force_n)
                .map_or(0, |f| f.hundredths_n().max(0).unsigned_abs()),
        })
        .collect();
    NodeConfig {
        id: node,
        link,
        actuators,
        firmware: options.firmware,
        noise_mm: options.noise_mm,
        force_noise_n: options.force_noise_n,
        protocol: options.protocol,
        seed: options.seed.wrapping_add(u64::from(node.get())),
    }
}

/// Checks the faults against the (validated) description, and powers every node on.
fn power_on(
    description: &FormDescription,
    link: Link,
    faults: &FaultSpec,
    options: &SimOptions,
    origin: Instant,
) -> Result<Vec<SharedNode>, SimError> {
    faults.check(description)?;
    let now = Instant::now();
    Ok(description
        .node_ids()
        .map(|id| {
            let node = Node::power_on(node_config(description, id, link, options), now);
            let schedule = NodeSchedule::for_node(faults, description, id);
            Arc::new(Mutex::new(NodeSim::new(node, schedule, origin)))
        })
        .collect())
}
