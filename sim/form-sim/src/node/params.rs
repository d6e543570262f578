//! Parameters: `ParamRead` / `ParamWrite` with the README's ids, scopes and ranges.

use firmware_protocol::drive::AckStatus;
use firmware_protocol::message::{Param, ParamRead};
use firmware_protocol::param::ParamId;
use firmware_protocol::timing::{FEEDBACK_PERIOD_MS, HEARTBEAT_PERIOD_MS, WATCHDOG_TIMEOUT_MS};
use tokio::time::{Duration, Instant};

use super::Node;
use super::actuator::{ActuatorConfig, ActuatorParams};

/// The node parameters (`0x00xx`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct NodeParams {
    /// Cyclic heartbeat period, ms (0 = off).
    pub heartbeat_ms: u16,
    /// Watchdog timeout, ms.
    pub watchdog_ms: u16,
    /// Cyclic feedback period, ms (0 = off).
    pub feedback_ms: u16,
}

impl Default for NodeParams {
    fn default() -> Self {
        Self {
            heartbeat_ms: HEARTBEAT_PERIOD_MS,
            watchdog_ms: WATCHDOG_TIMEOUT_MS,
            feedback_ms: FEEDBACK_PERIOD_MS,
        }
    }
}

/// When a cyclic frame last due at `due` is due next (`None`: the period is 0, off). A node
/// that fell behind does not send a burst to catch up.
pub(super) fn next_after(due: Instant, period_ms: u16, now: Instant) -> Option<Instant> {
    let period = Duration::from_millis(u64::from(period_ms));
    let next = due + period;
    (period_ms != 0).then_some(if next > now { next } else { now + period })
}

/// Range of the periods, ms.
const PERIOD_RANGE: std::ops::RangeInclusive<i32> = 0..=60_000;
/// Range of the watchdog timeout, ms.
const WATCHDOG_RANGE: std::ops::RangeInclusive<i32> = 10..=60_000;

impl Node {
    /// The value of a parameter, or why not.
    pub(super) fn read_param(&self, read: ParamRead) -> Result<i32, AckStatus> {
        if read.param.since_minor() > self.config.protocol.minor {
            return Err(AckStatus::UnknownParameter);
        }
        if read.param.is_per_actuator() {
            let actuator = read.actuator.ok_or(AckStatus::InvalidArgument)?;
            let a = self.actuators.get(actuator.index()).ok_or(AckStatus::InvalidArgument)?;
            let p = &a.params;
            let value = match read.param {
                ParamId::STROKE => a.config.stroke.hundredths_mm(),
                ParamId::SOFT_LIMIT_MIN => p.soft_min,
                ParamId::SOFT_LIMIT_MAX => p.soft_max,
                ParamId::MAX_SPEED => p.max_speed,
                ParamId::MAX_ACCEL => p.max_accel,
                ParamId::FOLLOWING_ERROR_LIMIT => p.following_error_limit,
                ParamId::HOMING_SPEED => p.homing_speed,
                ParamId::FORCE_LIMIT => p.force_limit,
                ParamId::RATED_FORCE => a.config.rated_force,
                _ => return Err(AckStatus::UnknownParameter),
            };
            return Ok(i32::from(value));
        }
        let value = match read.param {
            ParamId::HEARTBEAT_PERIOD => self.params.heartbeat_ms,
            ParamId::WATCHDOG_TIMEOUT => self.params.watchdog_ms,
            ParamId::FEEDBACK_PERIOD => self.params.feedback_ms,
            _ => return Err(AckStatus::UnknownParameter),
        };
        if read.actuator.is_some() {
            return Err(AckStatus::InvalidArgument);
        }
        Ok(i32::from(value))
    }

    /// Writes a parameter (for `None` on a per-actuator one: on every actuator, all or
    /// none), effective at once.
    pub(super) fn write_param(&mut self, now: Instant, write: Param) -> Result<(), AckStatus> {
        if write.param.since_minor() > self.config.protocol.minor {
            return Err(AckStatus::UnknownParameter);
        }
        if write.param.is_per_actuator() {
            let indices: Vec<usize> = match write.actuator {
                Some(a) if a.index() < self.actuators.len() => vec![a.index()],
                Some(_) => return Err(AckStatus::InvalidArgument),
                None => (0..self.actuators.len()).collect(),
            };
            let (speed, accel) = self.speed_and_accel_capability();
            let mut updated = Vec::with_capacity(indices.len());
            for &i in &indices {
                let a = &self.actuators[i];
                updated.push(set_actuator_param(a.params, &a.config, (speed, accel), write)?);
            }
            for (i, params) in indices.into_iter().zip(updated) {
                self.actuators[i].params = params;
            }
            return Ok(());
        }
        let (range, slot) = match write.param {
            ParamId::HEARTBEAT_PERIOD => (PERIOD_RANGE, &mut self.params.heartbeat_ms),
            ParamId::WATCHDOG_TIMEOUT => (WATCHDOG_RANGE, &mut self.params.watchdog_ms),
            ParamId::FEEDBACK_PERIOD => (PERIOD_RANGE, &mut self.params.feedback_ms),
            _ => return Err(AckStatus::UnknownParameter),
        };
        if write.actuator.is_some() || !range.contains(&write.value) {
            return Err(AckStatus::InvalidArgument);
        }
        *slot = write.value as u16;
        self.next_heartbeat = next_after(now, self.params.heartbeat_ms, now);
        self.next_feedback = next_after(now, self.params.feedback_ms, now);
        Ok(())
    }
}

/// `params` with one actuator parameter written, or why not.
fn set_actuator_param(
    mut params: ActuatorParams,
    config: &ActuatorConfig,
    (max_speed, max_accel): (u16, u16),
    write: Param,
) -> Result<ActuatorParams, AckStatus> {
    let value = write.value;
    let within = |lo: u16, hi: u16| {
        u16::try_from(value)
            .ok()
            .filter(|v| (lo..=hi).contains(v))
            .ok_or(AckStatus::InvalidArgument)
    };
    let stroke = config.stroke.hundredths_mm();
    match write.param {
        ParamId::STROKE | ParamId::RATED_FORCE => return Err(AckStatus::ReadOnlyParameter),
        ParamId::SOFT_LIMIT_MIN => params.soft_min = within(0, params.soft_max)?,
        ParamId::SOFT_LIMIT_MAX => params.soft_max = within(params.soft_min, stroke)?,
        ParamId::MAX_SPEED => params.max_speed = within(1, max_speed)?,
        ParamId::MAX_ACCEL => params.max_accel = within(1, max_accel)?,
        ParamId::FOLLOWING_ERROR_LIMIT => params.following_error_limit = within(1, u16::MAX - 1)?,
        ParamId::HOMING_SPEED => params.homing_speed = within(1, max_speed)?,
        ParamId::FORCE_LIMIT => params.force_limit = within(1, config.rated_force)?,
        _ => return Err(AckStatus::UnknownParameter),
    }
    Ok(params)
}
