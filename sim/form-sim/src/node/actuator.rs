//! One actuator of a node: its limits and parameters, its planned motion, and the physical
//! panel it moves (which a jam or a broken encoder makes part ways with the plan).

use firmware_protocol::update::shortest_duration_ms;
use firmware_protocol::{Accel, Force, HUNDREDTHS_PER_MM, HUNDREDTHS_PER_N, Position, Speed};
use tokio::time::Instant;

use super::motion::{Limits, Profile};

/// What an actuator's hardware can do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorConfig {
    /// Stroke: positions 0..=stroke.
    pub stroke: Position,
    /// Speed limit, 0.01 mm/s.
    pub max_speed: u16,
    /// Acceleration limit, 0.1 mm/s².
    pub max_accel: u16,
    /// Where the panel physically is at power-on, mm from home (before homing the node does
    /// not know it).
    pub start_mm: f64,
    /// The rated force of its drive and force sensor, 0.01 N: the default and highest
    /// `ForceLimit` (protocol 1.1).
    pub rated_force: u16,
}

/// A fault of the physical actuator, injected by a test or a fault spec.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ActuatorFault {
    /// The mechanism jams: the panel stops where it is and moves no more; the node sees a
    /// following error as soon as it commands a move (or homing).
    Stall,
    /// The position encoder fails: the node sees its reading jump by
    /// [`ENCODER_GLITCH_MM`], latches a following error at once and cannot reset it while
    /// the encoder stays broken.
    Encoder,
}

/// How far a failing encoder's reading jumps, mm.
pub const ENCODER_GLITCH_MM: f64 = 5.0;

/// The per-actuator parameters (`0x01xx`), in wire units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ActuatorParams {
    /// Lowest target accepted, 0.01 mm.
    pub soft_min: u16,
    /// Highest target accepted, 0.01 mm.
    pub soft_max: u16,
    /// Speed limit of the next moves, 0.01 mm/s.
    pub max_speed: u16,
    /// Acceleration limit of the next moves, 0.1 mm/s².
    pub max_accel: u16,
    /// Following error that latches `FOLLOWING_ERROR`, 0.01 mm.
    pub following_error_limit: u16,
    /// Homing speed, 0.01 mm/s.
    pub homing_speed: u16,
    /// The force that stalls the actuator, 0.01 N (protocol 1.1).
    pub force_limit: u16,
}

/// The default following error limit, 0.01 mm (1 mm).
const FOLLOWING_ERROR_LIMIT: u16 = 100;
/// The default homing speed, 0.01 mm/s (5 mm/s).
const HOMING_SPEED: u16 = 500;

/// Homing in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Homing {
    /// Creeping towards the home switch.
    Seek,
    /// The switch closed: braking and returning to position 0.
    Return,
}

/// An actuator: controller state and physical panel.
#[derive(Clone, Debug)]
pub(super) struct ActuatorSim {
    pub config: ActuatorConfig,
    pub params: ActuatorParams,
    /// The planned (commanded) motion, from `since`.
    profile: Profile,
    since: Instant,
    homing: Option<Homing>,
    /// The home is known (feedback is valid).
    pub homed: bool,
    /// The target waiting for SYNC.
    pub staged: Option<Position>,
    /// The panel is jammed at this position (mm).
    jammed_at: Option<f64>,
    /// The encoder is broken.
    pub encoder_broken: bool,
    /// The broken encoder has been reported since power-on.
    pub encoder_reported: bool,
    /// The external load on the panel, N, positive inwards (a garment squeezing the form);
    /// set by the simulated world around the node.
    pub load_n: f64,
}

impl ActuatorSim {
    /// A freshly powered actuator whose panel is at `position_mm`, holding, not homed.
    pub fn power_on(config: ActuatorConfig, capability: (u16, u16), now: Instant) -> Self {
        let (max_speed, max_accel) = capability;
        Self {
            config,
            params: ActuatorParams {
                soft_min: 0,
                soft_max: config.stroke.hundredths_mm(),
                max_speed,
                max_accel,
                following_error_limit: FOLLOWING_ERROR_LIMIT,
                homing_speed: HOMING_SPEED.min(max_speed),
                force_limit: config.rated_force,
            },
            profile: Profile::hold(config.start_mm),
            since: now,
            homing: None,
            homed: false,
            staged: None,
            jammed_at: None,
            encoder_broken: false,
            encoder_reported: false,
            load_n: 0.0,
        }
    }

    /// The same physical actuator after its node rebooted: the panel stays where it is (the
    /// drive is self-locking), the controller forgets everything.
    pub fn reboot(&self, capability: (u16, u16), now: Instant) -> Self {
        let position = self.position(now);
        let config = ActuatorConfig { start_mm: position, ..self.config };
        Self {
            jammed_at: self.jammed_at,
            encoder_broken: self.encoder_broken,
            load_n: self.load_n,
            ..Self::power_on(config, capability, now)
        }
    }

    fn elapsed(&self, now: Instant) -> f64 {
        now.saturating_duration_since(self.since).as_secs_f64()
    }

    /// The planned position (mm) and velocity (mm/s).
    pub fn planned(&self, now: Instant) -> (f64, f64) {
        let t = self.elapsed(now);
        (self.profile.position(t), self.profile.velocity(t))
    }

    /// Where the panel really is, mm.
    pub fn position(&self, now: Instant) -> f64 {
        self.jammed_at.unwrap_or_else(|| self.planned(now).0)
    }

    /// How fast the panel really moves, mm/s.
    pub fn velocity(&self, now: Instant) -> f64 {
        if self.jammed_at.is_some() { 0.0 } else { self.planned(now).1 }
    }

    /// Whether it is moving or homing (the heartbeat's *moving* set).
    pub fn is_moving(&self, now: Instant) -> bool {
        self.homing.is_some() || !self.profile.is_done(self.elapsed(now))
    }

    pub fn is_homing(&self) -> bool {
        self.homing.is_some()
    }

    pub fn is_jammed(&self) -> bool {
        self.jammed_at.is_some()
    }

    /// The limits of the next move, in mm/s and mm/s².
    fn limits(&self) -> Limits {
        Limits {
            speed: Speed::from_hundredths_mm_s(self.params.max_speed.max(1)).mm_s(),
            accel: Accel::from_tenths_mm_s2(self.params.max_accel.max(1)).mm_s2(),
        }
    }

    fn plan(&mut self, now: Instant, profile: Profile) {
        self.profile = profile;
        self.since = now;
    }

    /// Stops at the acceleration limit, abandoning a move or homing.
    pub fn brake(&mut self, now: Instant) {
        let (p, v) = self.planned(now);
        self.homing = None;
        self.plan(now, Profile::ramp(p, v, 0.0, self.limits().accel));
    }

    /// Stalls against a load over its force limit: stops where it is at once (the motor
    /// cannot push on) and holds, abandoning a move or homing.
    pub fn stall(&mut self, now: Instant) {
        let position = self.position(now);
        self.homing = None;
        self.staged = None;
        self.plan(now, Profile::hold(position));
    }

    /// Whether the load is over the force limit, either way (pushing the panel in, or
    /// pulling it out).
    pub fn over_force(&self) -> bool {
        self.load_n.abs() * HUNDREDTHS_PER_N > f64::from(self.params.force_limit)
    }

    /// The force reading: the load plus `noise` (N), to 0.01 N.
    pub fn measured_force(&self, noise: f64) -> Option<Force> {
        Force::from_n(self.load_n + noise)
    }

    /// Starts the move to `target` lasting `duration_ms` (0: as fast as possible). Returns
    /// the shortest feasible duration if `duration_ms` is shorter (it then moves at its
    /// limits and arrives late).
    pub fn start_move(&mut self, now: Instant, target: Position, duration_ms: u16) -> Option<u32> {
        let (p0, v0) = self.planned(now);
        let limits = self.limits();
        let p1 = target.mm();
        let fastest = Profile::fastest(p0, v0, p1, limits);
        let required_ms = if v0 == 0.0 {
            // From rest host and node share one integer formula.
            let from = (p0 * HUNDREDTHS_PER_MM).round().clamp(0.0, f64::from(u16::MAX)) as u16;
            let distance = target.hundredths_mm().abs_diff(from);
            let speed = Speed::from_hundredths_mm_s(self.params.max_speed);
            let accel = Accel::from_tenths_mm_s2(self.params.max_accel);
            shortest_duration_ms(distance, speed, accel).unwrap_or(u32::MAX)
        } else {
            let shortest = super::motion::shortest_time(v0, p1 - p0, limits);
            (shortest * 1000.0).ceil() as u32
        };
        let too_short = duration_ms != 0 && u32::from(duration_ms) < required_ms;
        let profile = if duration_ms == 0 || too_short {
            fastest
        } else {
            Profile::timed(p0, v0, p1, f64::from(duration_ms) / 1000.0, limits)
        };
        self.plan(now, profile);
        too_short.then_some(required_ms)
    }

    /// Starts homing: forget the home and creep towards the home switch.
    pub fn start_homing(&mut self, now: Instant) {
        let (p, v) = self.planned(now);
        let speed =
            Speed::from_hundredths_mm_s(self.params.homing_speed.min(self.params.max_speed)).mm_s();
        self.homed = false;
        self.staged = None;
        self.homing = Some(Homing::Seek);
        self.plan(now, Profile::ramp(p, v, -speed, self.limits().accel));
    }

    /// Follows homing: at the switch (position 0) brake and come back to 0; returns true when
    /// homing has just finished.
    pub fn update_homing(&mut self, now: Instant) -> bool {
        match self.homing {
            Some(Homing::Seek) if self.position(now) <= 0.0 => {
                let (p, v) = self.planned(now);
                self.homing = Some(Homing::Return);
                self.plan(now, Profile::fastest(p, v, 0.0, self.limits()));
                false
            }
            Some(Homing::Return) if self.profile.is_done(self.elapsed(now)) => {
                self.homing = None;
                self.homed = true;
                true
            }
            _ => false,
        }
    }

    /// How far the panel lags the plan, 0.01 mm.
    pub fn following_error(&self, now: Instant) -> f64 {
        (self.planned(now).0 - self.position(now)).abs() * HUNDREDTHS_PER_MM
    }

    /// After a following error: the position is lost, the plan resets to where the panel is.
    pub fn lose_position(&mut self, now: Instant) {
        let position = self.position(now);
        self.homing = None;
        self.homed = false;
        self.staged = None;
        self.plan(now, Profile::hold(position));
    }

    /// Injects a physical fault.
    pub fn inject(&mut self, now: Instant, fault: ActuatorFault) {
        match fault {
            ActuatorFault::Stall => self.jammed_at = Some(self.position(now)),
            ActuatorFault::Encoder => self.encoder_broken = true,
        }
    }

    /// Repairs the mechanism and the encoder (a technician freed the jam, replaced the
    /// encoder): the panel holds where it is; a latched fault stays until a FaultReset.
    pub fn repair(&mut self, now: Instant) {
        if self.jammed_at.is_some() {
            let position = self.position(now);
            self.jammed_at = None;
            self.plan(now, Profile::hold(position));
        }
        self.encoder_broken = false;
        self.encoder_reported = false;
    }

    /// The feedback position: the panel's position plus `noise` (mm), to 0.01 mm; `None`
    /// when not homed.
    pub fn measured(&self, now: Instant, noise: f64) -> Option<Position> {
        if !self.homed || self.encoder_broken {
            return None;
        }
        let max = f64::from(Position::MAX.hundredths_mm());
        let hundredths = ((self.position(now) + noise) * HUNDREDTHS_PER_MM).round().clamp(0.0, max);
        Position::new(hundredths as u16)
    }
}
