//! Motion profiles within speed and acceleration limits.
//!
//! A [`Profile`] is a piecewise-linear velocity (constant acceleration between knots),
//! integrated exactly, so a position can be read at any instant without stepping. A move
//! from position `p0` at velocity `v0` to rest at `p1` after exactly `T` uses
//!
//! ```text
//! v(t) = clamp( clamp(vc, v0 − A·t, v0 + A·t),  −A·(T − t),  A·(T − t) )
//! ```
//!
//! — ramp at the acceleration limit `A` from `v0` towards a cruise velocity `vc`, cruise, and
//! ramp down at `A` to rest at `T`: the reference trapezoid (a triangle when short), which
//! also covers retargeting a moving actuator (it may brake and reverse). For a fixed `T` the
//! distance covered grows monotonically with `vc`, so `vc ∈ [−V, V]` is found by bisection;
//! the shortest feasible `T` likewise. Every profile keeps |a| ≤ `A`, and |v| ≤ `V` unless
//! it starts faster (then it only slows down).

/// Speed and acceleration limits of one move, mm/s and mm/s².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Speed limit, mm/s (> 0).
    pub speed: f64,
    /// Acceleration and deceleration limit, mm/s² (> 0).
    pub accel: f64,
}

/// A point where the acceleration may change.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Knot {
    /// Seconds from the profile's start.
    t: f64,
    /// Velocity, mm/s.
    v: f64,
    /// Position, mm.
    p: f64,
}

/// A velocity profile: linear between knots, constant after the last one.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    knots: Vec<Knot>,
}

/// Bisection steps: halves a ±655 mm/s (or ±1000 s) interval below 1e-15.
const BISECTIONS: usize = 64;
/// The shortest first guess at a move's duration, s: a millisecond, the wire's unit of
/// durations, so that a move of nothing from rest still brackets.
const MIN_GUESS_S: f64 = 1e-3;
/// The longest duration the bracket grows to, s: far beyond any move (the wire's durations
/// end at 65.535 s); a guard against a loop that could not end on bad limits.
const MAX_BRACKET_S: f64 = 1e9;
/// Knot times closer than this are one, s: far below the node's 1 ms tick, above the
/// rounding of sums of a few seconds in `f64`.
const SAME_TIME_S: f64 = 1e-12;

impl Profile {
    /// Standing still at `p`.
    pub fn hold(p: f64) -> Self {
        Self { knots: vec![Knot { t: 0.0, v: 0.0, p }] }
    }

    /// From `p0` at `v0`, change velocity at `accel` to `v` and keep it (homing, braking).
    pub fn ramp(p0: f64, v0: f64, v: f64, accel: f64) -> Self {
        let t = (v - v0).abs() / accel;
        let start = Knot { t: 0.0, v: v0, p: p0 };
        Self { knots: vec![start, Knot { t, v, p: p0 + (v0 + v) / 2.0 * t }] }
    }

    /// From `p0` at `v0` to rest at `p1` as fast as `limits` allow.
    pub fn fastest(p0: f64, v0: f64, p1: f64, limits: Limits) -> Self {
        Self::timed(p0, v0, p1, shortest_time(v0, p1 - p0, limits), limits)
    }

    /// From `p0` at `v0` to rest at `p1` in `duration` s, or in the shortest feasible time if
    /// longer.
    pub fn timed(p0: f64, v0: f64, p1: f64, duration: f64, limits: Limits) -> Self {
        let duration = duration.max(shortest_time(v0, p1 - p0, limits));
        let distance = p1 - p0;
        let (mut lo, mut hi) = (-limits.speed, limits.speed);
        for _ in 0..BISECTIONS {
            let mid = (lo + hi) / 2.0;
            if covered(v0, mid, duration, limits.accel) < distance {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mut knots = knots(p0, v0, (lo + hi) / 2.0, duration, limits.accel);
        // Arrive exactly (the bisection leaves an error of the order of 1e-12 mm).
        if let Some(last) = knots.last_mut() {
            last.p = p1;
        }
        Self { knots }
    }

    /// Position (mm) `t` s after the start.
    pub fn position(&self, t: f64) -> f64 {
        let (k, dt, accel) = self.segment(t);
        k.p + k.v * dt + accel * dt * dt / 2.0
    }

    /// Velocity (mm/s) `t` s after the start.
    pub fn velocity(&self, t: f64) -> f64 {
        let (k, dt, accel) = self.segment(t);
        k.v + accel * dt
    }

    /// Whether the profile has come to rest for good by `t`.
    pub fn is_done(&self, t: f64) -> bool {
        self.knots.last().is_none_or(|k| k.v == 0.0 && t >= k.t)
    }

    /// The knot at or before `t`, the time since it and the acceleration after it.
    fn segment(&self, t: f64) -> (Knot, f64, f64) {
        let t = t.max(0.0);
        for pair in self.knots.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            if t < b.t {
                return (a, t - a.t, (b.v - a.v) / (b.t - a.t));
            }
        }
        let last = self.knots.last().copied().unwrap_or(Knot { t: 0.0, v: 0.0, p: 0.0 });
        (last, t - last.t, 0.0)
    }
}

/// The shortest time (s) to go `distance` mm from velocity `v0` to rest within `limits`.
pub fn shortest_time(v0: f64, distance: f64, limits: Limits) -> f64 {
    let feasible = |t: f64| {
        covered(v0, -limits.speed, t, limits.accel) <= distance
            && distance <= covered(v0, limits.speed, t, limits.accel)
    };
    // A move must at least stop.
    let lo = v0.abs() / limits.accel;
    if feasible(lo) {
        return lo;
    }
    let mut lo = lo;
    let mut hi =
        lo + (distance.abs() / limits.speed + 2.0 * limits.speed / limits.accel).max(MIN_GUESS_S);
    while !feasible(hi) && hi < MAX_BRACKET_S {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..BISECTIONS {
        let mid = (lo + hi) / 2.0;
        if feasible(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Distance (mm) covered in `duration` by the profile with cruise velocity `vc`.
fn covered(v0: f64, vc: f64, duration: f64, accel: f64) -> f64 {
    let knots = knots(0.0, v0, vc, duration, accel);
    knots.last().map_or(0.0, |k| k.p)
}

/// The knots of the move profile with cruise velocity `vc` (see the module docs).
fn knots(p0: f64, v0: f64, vc: f64, duration: f64, accel: f64) -> Vec<Knot> {
    let (a, t_end) = (accel, duration);
    let velocity = |t: f64| {
        let inner = vc.clamp(v0 - a * t, v0 + a * t);
        let room = a * (t_end - t);
        inner.clamp(-room, room)
    };
    // Every time where one of the clamped lines crosses another: between them v is linear.
    let mut times = vec![
        0.0,
        t_end,
        (vc - v0).abs() / a,
        t_end - vc / a,
        t_end + vc / a,
        (a * t_end - v0) / (2.0 * a),
        (a * t_end + v0) / (2.0 * a),
    ];
    times.retain(|t| (0.0..=t_end).contains(t));
    times.sort_by(f64::total_cmp);
    times.dedup_by(|x, y| (*x - *y).abs() < SAME_TIME_S);
    let mut knots: Vec<Knot> = Vec::with_capacity(times.len());
    for t in times {
        // Start at v0 exactly, and end at rest exactly.
        let v = if t == 0.0 {
            v0
        } else if t == t_end {
            0.0
        } else {
            velocity(t)
        };
        let p = knots.last().map_or(p0, |k| k.p + (k.v + v) / 2.0 * (t - k.t));
        knots.push(Knot { t, v, p });
    }
    knots
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_protocol::{Accel, Speed};

    const LIMITS: Limits = Limits { speed: 10.0, accel: 100.0 };

    /// Samples (velocity, acceleration) every millisecond up to `until`.
    fn samples(profile: &Profile, until: f64) -> Vec<(f64, f64)> {
        let dt = 1e-3;
        (0..(until / dt) as usize)
            .map(|i| {
                let t = i as f64 * dt;
                let v = profile.velocity(t);
                (v, (profile.velocity(t + dt) - v) / dt)
            })
            .collect()
    }

    #[test]
    fn a_move_from_rest_matches_the_protocols_shortest_duration() {
        // 50 mm at 10 mm/s with 100 mm/s²: 5.1 s, as `update::shortest_duration_ms` says.
        let t = shortest_time(0.0, 50.0, LIMITS);
        assert!((t - 5.1).abs() < 1e-9, "{t}");
        let (speed, accel) = (Speed::from_mm_s(10.0).unwrap(), Accel::from_mm_s2(100.0).unwrap());
        assert_eq!(firmware_protocol::update::shortest_duration_ms(5000, speed, accel), Some(5100));
        // A triangle: 1 mm takes 2·√(1/100) = 0.2 s.
        assert!((shortest_time(0.0, 1.0, LIMITS) - 0.2).abs() < 1e-9);
    }

    #[test]
    fn a_timed_move_arrives_on_time_at_rest_within_the_limits() {
        let profile = Profile::timed(3.0, 0.0, 40.0, 6.0, LIMITS);
        assert_eq!(profile.position(6.0), 40.0);
        assert_eq!(profile.velocity(6.0), 0.0);
        assert!(profile.is_done(6.0) && !profile.is_done(5.99));
        assert!((profile.position(5.999) - 40.0).abs() < 1e-3);
        for (v, a) in samples(&profile, 6.5) {
            assert!(v.abs() <= LIMITS.speed + 1e-9 && a.abs() <= LIMITS.accel + 1e-6, "{v} {a}");
        }
    }

    #[test]
    fn a_too_short_duration_is_stretched_to_the_shortest() {
        let profile = Profile::timed(0.0, 0.0, 50.0, 1.0, LIMITS);
        assert!(!profile.is_done(5.0));
        assert!(profile.is_done(5.1 + 1e-9));
    }

    #[test]
    fn retargeting_a_moving_actuator_brakes_and_reverses_within_the_limits() {
        // Moving up at full speed, asked to go back below where it is.
        let profile = Profile::fastest(20.0, 10.0, 10.0, LIMITS);
        let (v0, p0) = (profile.velocity(0.0), profile.position(0.0));
        assert_eq!((v0, p0), (10.0, 20.0));
        // It overshoots by v²/2a = 0.5 mm before reversing.
        let peak = (0..2000).map(|i| profile.position(i as f64 * 1e-3)).fold(f64::MIN, f64::max);
        assert!((peak - 20.5).abs() < 1e-3, "{peak}");
        for (v, a) in samples(&profile, 3.0) {
            assert!(v.abs() <= LIMITS.speed + 1e-9 && a.abs() <= LIMITS.accel + 1e-6, "{v} {a}");
        }
        let end = shortest_time(10.0, -10.0, LIMITS);
        assert_eq!(profile.position(end), 10.0);
    }

    #[test]
    fn braking_stops_at_the_acceleration_limit() {
        let brake = Profile::ramp(5.0, -10.0, 0.0, LIMITS.accel);
        assert!(brake.is_done(0.1) && !brake.is_done(0.099));
        assert!((brake.position(1.0) - 4.5).abs() < 1e-12);
    }

    #[test]
    fn every_timed_move_keeps_the_limits() {
        let mut seed = 0x2545_f491_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f64 / 10_000.0
        };
        for _ in 0..300 {
            let limits = Limits { speed: 5.0 + 15.0 * next(), accel: 20.0 + 80.0 * next() };
            let (p0, p1) = (60.0 * next(), 60.0 * next());
            let v0 = limits.speed * (2.0 * next() - 1.0);
            let duration = 8.0 * next();
            let profile = Profile::timed(p0, v0, p1, duration, limits);
            let end = duration.max(shortest_time(v0, p1 - p0, limits));
            assert_eq!(profile.position(end), p1);
            assert!(profile.is_done(end));
            for (v, a) in samples(&profile, end + 0.01) {
                assert!(v.abs() <= limits.speed + 1e-9, "{v} {limits:?}");
                assert!(a.abs() <= limits.accel * (1.0 + 1e-6), "{a} {limits:?}");
            }
        }
    }
}
