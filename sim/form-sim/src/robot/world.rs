//! The world around the nodes: a garment on the form, pressing on its panels.
//!
//! The load on a panel depends on every panel of its ring, which several nodes drive, so no
//! node can compute it: every tick the world reads where every panel is (each node locked in
//! turn, never two at once), puts the garment's bands on the rings ([`band_load`]), and hands
//! each node its actuators' loads, which the node checks at its next tick. A node thus feels
//! the garment at most two ticks late (0.06 mm of travel at the reference form's fastest
//! 30 mm/s and the default 1 ms tick). The world never moves a node's clock: after the
//! simulator stood still, only the node's runner, which excuses the stall, may.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use firmware_protocol::Actuator;
use form_description::FormDescription;
use tokio::time::{Duration, Instant, MissedTickBehavior, interval};

use super::runners::{SharedNode, lock};
use crate::garment::{GarmentSpec, band_load};

/// What the form wears, shared by the world and [`SimulatedForm`](super::SimulatedForm)
/// (which dresses and undresses it).
pub(crate) type SharedGarment = Arc<Mutex<Option<GarmentSpec>>>;

/// Every actuator's load under `garment` with the panels at `positions_mm`, N (id → load;
/// actuators outside the garment's bands carry nothing).
pub fn loads(
    form: &FormDescription,
    garment: &GarmentSpec,
    positions_mm: &BTreeMap<String, f64>,
) -> BTreeMap<String, f64> {
    garment
        .bands
        .iter()
        .filter_map(|band| band_load(form, band, positions_mm))
        .flat_map(|load| load.panels)
        .map(|panel| (panel.actuator, panel.force_n))
        .collect()
}

/// Puts the garment's load on the nodes every `tick`, forever (the task is aborted with the
/// form).
pub(crate) async fn run(
    form: FormDescription,
    nodes: Vec<SharedNode>,
    garment: SharedGarment,
    tick: Duration,
) {
    let mut ticker = interval(tick);
    ticker.set_missed_tick_behavior(MissedTickBehavior::Delay);
    // Whether the loads are zero and no garment is worn.
    let mut bare = false;
    loop {
        ticker.tick().await;
        let now = Instant::now();
        let Some(worn) = lock(&garment).clone() else {
            // Nothing worn: the loads are zero once, then nothing to do.
            if !bare {
                for node in &nodes {
                    let mut sim = lock(node);
                    Actuator::all().for_each(|index| sim.node.apply_load(index, 0.0));
                }
                bare = true;
            }
            continue;
        };
        bare = false;
        let mut positions = BTreeMap::new();
        for node in &nodes {
            let sim = lock(node);
            let id = sim.node.id();
            for (index, state) in Actuator::all().zip(sim.node.actuator_states(now)) {
                if let Some(axis) = form.actuator_at(id, index) {
                    positions.insert(axis.id.to_string(), state.position_mm);
                }
            }
        }
        let loads = loads(&form, &worn, &positions);
        for node in &nodes {
            let mut sim = lock(node);
            let id = sim.node.id();
            for index in Actuator::all() {
                let Some(axis) = form.actuator_at(id, index) else { continue };
                let load = loads.get(axis.id).copied().unwrap_or(0.0);
                sim.node.apply_load(index, load);
            }
        }
    }
}
