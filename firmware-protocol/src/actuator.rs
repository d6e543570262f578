//! Actuators of a node, sets of them, positions along their stroke, their speed and
//! acceleration limits ([`Speed`] in 0.01 mm/s, [`Accel`] in 0.1 mm/s²), and the forces they
//! measure ([`Force`] in 0.01 N, protocol 1.1).
//!
//! A node drives at most [`MAX_ACTUATORS`] (8) linear actuators, numbered 0..=7. A board with
//! more actuators presents itself as several nodes (as ODrive does with its two axes).
//!
//! Positions are `u16` in **0.01 mm**, measured from the actuator's home (fully retracted) end
//! outwards, so 0..=655.34 mm; the wire value `0xFFFF` is reserved and means "no position"
//! ("keep the staged target" in set-points, "unknown, not homed" in feedback). In Rust that is
//! an `Option<Position>`.

/// The most actuators one node drives.
pub const MAX_ACTUATORS: usize = 8;

/// The wire value of "no position" (`None`).
pub(crate) const NO_POSITION: u16 = 0xFFFF;

/// One actuator of a node, by index 0..=7.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Actuator(u8);

impl Actuator {
    /// The actuator with this index, if it is below [`MAX_ACTUATORS`].
    pub const fn new(index: u8) -> Option<Self> {
        if (index as usize) < MAX_ACTUATORS { Some(Self(index)) } else { None }
    }

    /// The index, 0..=7.
    pub const fn index(self) -> usize {
        self.0 as usize
    }

    /// Every actuator a node can have, 0..=7.
    pub fn all() -> impl Iterator<Item = Actuator> {
        (0..MAX_ACTUATORS as u8).map(Actuator)
    }
}

/// The wire value of an "actuator or the whole node" field: 0..=7, or 0xFF for the node.
pub(crate) const fn actuator_to_wire(actuator: Option<Actuator>) -> u8 {
    match actuator {
        Some(a) => a.0,
        None => 0xFF,
    }
}

/// Decodes an "actuator or the whole node" field; `Err(())` for 8..=0xFE.
pub(crate) const fn actuator_from_wire(raw: u8) -> Result<Option<Actuator>, ()> {
    match raw {
        0xFF => Ok(None),
        _ => match Actuator::new(raw) {
            Some(a) => Ok(Some(a)),
            None => Err(()),
        },
    }
}

/// A set of a node's actuators, as a bit mask: bit `i` is actuator `i`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ActuatorSet(u8);

impl ActuatorSet {
    /// No actuator.
    pub const EMPTY: Self = Self(0);
    /// All eight actuators (bits a node does not have are ignored by it).
    pub const ALL: Self = Self(0xFF);

    /// The set with this bit mask.
    pub const fn from_bits(bits: u8) -> Self {
        Self(bits)
    }

    /// The bit mask.
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Whether the set holds no actuator.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether `actuator` is in the set.
    pub const fn contains(self, actuator: Actuator) -> bool {
        self.0 & (1 << actuator.0) != 0
    }

    /// The set with `actuator` added.
    pub const fn with(self, actuator: Actuator) -> Self {
        Self(self.0 | 1 << actuator.0)
    }

    /// The actuators in the set, lowest index first.
    pub fn iter(self) -> impl Iterator<Item = Actuator> {
        Actuator::all().filter(move |&a| self.contains(a))
    }
}

impl FromIterator<Actuator> for ActuatorSet {
    fn from_iter<I: IntoIterator<Item = Actuator>>(iter: I) -> Self {
        iter.into_iter().fold(Self::EMPTY, Self::with)
    }
}

/// Hundredths of a millimetre in one: the wire's unit of length (positions, and the details
/// of emergencies about lengths) and of speed (0.01 mm/s). The one conversion factor between
/// the wire's lengths and millimetres, for host and nodes alike.
pub const HUNDREDTHS_PER_MM: f64 = 100.0;

/// Tenths of a mm/s² in one: the wire's unit of acceleration (0.1 mm/s²).
pub const TENTHS_PER_MM_S2: f64 = 10.0;

/// A position along an actuator's stroke: 0.01 mm from its home end, at most 655.34 mm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Position(u16);

impl Position {
    /// The home (fully retracted) end of the stroke.
    pub const ZERO: Self = Self(0);
    /// The largest position the wire can carry, 655.34 mm.
    pub const MAX: Self = Self(NO_POSITION - 1);

    /// The position `hundredths_mm` × 0.01 mm, if at most [`Position::MAX`].
    pub const fn new(hundredths_mm: u16) -> Option<Self> {
        if hundredths_mm == NO_POSITION { None } else { Some(Self(hundredths_mm)) }
    }

    /// The position rounded to 0.01 mm, if `mm` is a number in 0..=655.34.
    pub fn from_mm(mm: f32) -> Option<Self> {
        let hundredths = mm * HUNDREDTHS_PER_MM as f32 + 0.5;
        // The negated comparison also rejects NaN.
        if !(0.0..(NO_POSITION as f32)).contains(&hundredths) {
            return None;
        }
        Some(Self(hundredths as u16))
    }

    /// The position in 0.01 mm.
    pub const fn hundredths_mm(self) -> u16 {
        self.0
    }

    /// The position in millimetres (exactly the nearest `f64` to the decimal value: the one
    /// conversion from the wire's hundredths the host uses).
    pub fn mm(self) -> f64 {
        f64::from(self.0) / HUNDREDTHS_PER_MM
    }
}

/// `x` rounded to the nearest whole number (halves up) if that fits a `u16` wire value. By
/// hand because `f64::round` needs `std` (or libm), and this crate builds for `no_std`
/// targets: for `x` in -0.5..65535.5, adding a half and truncating is rounding.
fn round_to_wire(x: f64) -> Option<u16> {
    // The negated comparison also rejects NaN.
    if !(-0.5..f64::from(u16::MAX) + 0.5).contains(&x) {
        return None;
    }
    Some((x + 0.5) as u16)
}

/// A speed (limit), in the wire's unit of **0.01 mm/s**: 0..=655.35 mm/s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Speed(u16);

impl Speed {
    /// The speed `hundredths_mm_s` × 0.01 mm/s.
    pub const fn from_hundredths_mm_s(hundredths_mm_s: u16) -> Self {
        Self(hundredths_mm_s)
    }

    /// The speed rounded to 0.01 mm/s, if `mm_s` is a number in 0..=655.35.
    pub fn from_mm_s(mm_s: f64) -> Option<Self> {
        round_to_wire(mm_s * HUNDREDTHS_PER_MM).map(Self)
    }

    /// The speed in 0.01 mm/s (the wire value).
    pub const fn hundredths_mm_s(self) -> u16 {
        self.0
    }

    /// The speed in mm/s.
    pub fn mm_s(self) -> f64 {
        f64::from(self.0) / HUNDREDTHS_PER_MM
    }
}

/// An acceleration (limit, also for deceleration), in the wire's unit of **0.1 mm/s²**:
/// 0..=6553.5 mm/s².
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Accel(u16);

impl Accel {
    /// The acceleration `tenths_mm_s2` × 0.1 mm/s².
    pub const fn from_tenths_mm_s2(tenths_mm_s2: u16) -> Self {
        Self(tenths_mm_s2)
    }

    /// The acceleration rounded to 0.1 mm/s², if `mm_s2` is a number in 0..=6553.5.
    pub fn from_mm_s2(mm_s2: f64) -> Option<Self> {
        round_to_wire(mm_s2 * TENTHS_PER_MM_S2).map(Self)
    }

    /// The acceleration in 0.1 mm/s² (the wire value).
    pub const fn tenths_mm_s2(self) -> u16 {
        self.0
    }

    /// The acceleration in mm/s².
    pub fn mm_s2(self) -> f64 {
        f64::from(self.0) / TENTHS_PER_MM_S2
    }
}

/// Hundredths of a newton in one: the wire's unit of force (protocol 1.1).
pub const HUNDREDTHS_PER_N: f64 = 100.0;

/// The wire value of "no force measured" (`None`): the most negative `i16`.
pub(crate) const NO_FORCE: i16 = i16::MIN;

/// A force an actuator measures (protocol 1.1), in the wire's unit of **0.01 N**, signed:
/// positive when the load pushes the panel inwards, towards home (a garment squeezing the
/// form), negative when it pulls it outwards. −327.67..=327.67 N; the wire value `0x8000`
/// is reserved and means "not measured" (`None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Force(i16);

impl Force {
    /// No load.
    pub const ZERO: Self = Self(0);
    /// The largest force the wire carries, 327.67 N.
    pub const MAX: Self = Self(i16::MAX);

    /// The force `hundredths_n` × 0.01 N, unless it is the reserved `i16::MIN`.
    pub const fn new(hundredths_n: i16) -> Option<Self> {
        if hundredths_n == NO_FORCE { None } else { Some(Self(hundredths_n)) }
    }

    /// The force rounded to 0.01 N and saturated at ±327.67 N (a sensor reads its full
    /// scale beyond its range); `None` for NaN.
    pub fn from_n(n: f64) -> Option<Self> {
        if n.is_nan() {
            return None;
        }
        let max = f64::from(i16::MAX);
        let hundredths = (n * HUNDREDTHS_PER_N).clamp(-max, max);
        // Rounding half away from zero by hand (`f64::round` needs std): |x| ≤ 32767.
        let rounded = if hundredths < 0.0 { hundredths - 0.5 } else { hundredths + 0.5 };
        Some(Self(rounded as i16))
    }

    /// The force in 0.01 N (the wire value).
    pub const fn hundredths_n(self) -> i16 {
        self.0
    }

    /// The force in newtons.
    pub fn n(self) -> f64 {
        f64::from(self.0) / HUNDREDTHS_PER_N
    }
}

/// The wire value of a force slot.
pub(crate) const fn force_to_wire(force: Option<Force>) -> i16 {
    match force {
        Some(f) => f.0,
        None => NO_FORCE,
    }
}

/// The wire value of a position slot.
pub(crate) const fn position_to_wire(position: Option<Position>) -> u16 {
    match position {
        Some(p) => p.0,
        None => NO_POSITION,
    }
}

/// Decodes a position slot; every `u16` is valid.
pub(crate) const fn position_from_wire(raw: u16) -> Option<Position> {
    Position::new(raw)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn actuator_indices_stop_at_eight() {
        assert_eq!(Actuator::new(7).map(Actuator::index), Some(7));
        assert_eq!(Actuator::new(8), None);
        assert_eq!(Actuator::all().count(), MAX_ACTUATORS);
    }

    #[test]
    fn node_wide_actuator_field_is_0xff_and_8_to_0xfe_are_invalid() {
        assert_eq!(actuator_to_wire(None), 0xFF);
        assert_eq!(actuator_from_wire(0xFF), Ok(None));
        assert_eq!(actuator_from_wire(3), Ok(Actuator::new(3)));
        assert!((8..=0xFE).all(|raw| actuator_from_wire(raw).is_err()));
    }

    #[test]
    fn actuator_sets_are_bit_masks() {
        let set: ActuatorSet = [1, 6].into_iter().filter_map(Actuator::new).collect();
        assert_eq!(set.bits(), 0b0100_0010);
        assert!(set.contains(Actuator::new(6).unwrap()));
        assert!(!set.contains(Actuator::new(0).unwrap()));
        assert_eq!(set.iter().map(Actuator::index).collect::<Vec<_>>(), [1, 6]);
        assert!(ActuatorSet::EMPTY.is_empty() && !ActuatorSet::ALL.is_empty());
    }

    #[test]
    fn forces_round_to_hundredths_saturate_and_reserve_0x8000() {
        assert_eq!(Force::from_n(12.345).map(Force::hundredths_n), Some(1235));
        assert_eq!(Force::from_n(-0.004).map(Force::hundredths_n), Some(0));
        assert_eq!(Force::from_n(-1.006).map(Force::hundredths_n), Some(-101));
        assert_eq!(Force::from_n(1e9), Some(Force::MAX));
        assert_eq!(Force::from_n(-1e9).map(Force::hundredths_n), Some(-i16::MAX));
        assert_eq!(Force::from_n(f64::NAN), None);
        assert_eq!(Force::new(i16::MIN), None);
        assert_eq!(force_to_wire(None), i16::MIN);
        assert_eq!(Force::new(-250).map(Force::n), Some(-2.5));
    }

    #[test]
    fn positions_round_to_hundredths_and_reserve_0xffff() {
        assert_eq!(Position::from_mm(12.345).map(Position::hundredths_mm), Some(1235));
        assert_eq!(Position::from_mm(0.0), Some(Position::ZERO));
        assert_eq!(Position::from_mm(655.34), Some(Position::MAX));
        assert_eq!(Position::from_mm(655.35), None);
        assert_eq!(Position::from_mm(-0.01), None);
        assert_eq!(Position::from_mm(f32::NAN), None);
        assert_eq!(Position::new(0xFFFF), None);
        assert_eq!(position_from_wire(position_to_wire(None)), None);
        assert!((Position::new(2550).unwrap().mm() - 25.5).abs() < 1e-6);
    }

    #[test]
    fn speeds_and_accelerations_carry_their_units() {
        assert_eq!(Speed::from_mm_s(12.0).map(Speed::hundredths_mm_s), Some(1200));
        assert_eq!(Speed::from_mm_s(655.35), Some(Speed::from_hundredths_mm_s(u16::MAX)));
        assert_eq!(Speed::from_mm_s(655.36), None);
        assert_eq!(Speed::from_mm_s(f64::NAN), None);
        assert_eq!(Speed::from_hundredths_mm_s(1250).mm_s(), 12.5);
        assert_eq!(Accel::from_mm_s2(50.0).map(Accel::tenths_mm_s2), Some(500));
        assert_eq!(Accel::from_mm_s2(-0.1), None);
        assert_eq!(Accel::from_tenths_mm_s2(505).mm_s2(), 50.5);
    }
}
