//! The spine's and the neck's pose as warps of space: the body is designed upright, facing
//! forward, and its upper parts are then bent sideways and twisted by the spine and turned by
//! the neck. Each part of the implicit body is evaluated at the point its own warp brings
//! back to the upright design (the inverse warp), so the field stays exact on the design.
//!
//! - **Twist** (axial rotation of the spine): about the vertical axis x = y = 0, by an angle
//!   that rises smoothly (smoothstep) from 0 at the bottom of the spine's band to the full
//!   angle at its top, constant above; positive turns the shoulders towards the subject's
//!   left (counter-clockwise seen from above).
//! - **Lateral bend**: the spine's band bends as an arc of constant curvature in the frontal
//!   plane (Barr's bend), the part above it moving rigidly with the arc's end; positive bends
//!   towards the subject's left (+X).
//! - **Head turn**: the head and neck turn rigidly about the neck's vertical axis; positive
//!   turns the face towards the subject's left.
//!
//! Below the band nothing moves: the hips, buttocks and legs stay as designed.

use glam::{DQuat, DVec3};

/// The spine's and neck's pose, in the design's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SpineWarp {
    /// Bottom and top of the spine's band (mm): the bend and twist happen between them.
    pub band: (f64, f64),
    /// Lateral bend over the band (radians), positive towards +X.
    pub bend: f64,
    /// Twist over the band (radians), positive counter-clockwise seen from above.
    pub twist: f64,
    /// The neck's vertical axis (x, y) and the head's turn about it (radians).
    pub neck_axis: (f64, f64),
    pub head_turn: f64,
}

/// What a part of the body moves with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Segment {
    /// Hips and legs: not moved.
    Pelvis,
    /// Torso and arms: bent and twisted with the spine.
    Trunk,
    /// Neck and head: with the trunk, and turned.
    Head,
}

/// Below this bend (radians) the band is straight: the arc's radius would exceed any body.
const STRAIGHT: f64 = 1e-9;

impl SpineWarp {
    /// No pose: everything stays where it was designed.
    #[cfg(test)]
    pub fn upright() -> SpineWarp {
        SpineWarp { band: (0.0, 1.0), bend: 0.0, twist: 0.0, neck_axis: (0.0, 0.0), head_turn: 0.0 }
    }

    /// Whether the spine is straight and untwisted (the head may still be turned).
    pub fn spine_is_straight(&self) -> bool {
        self.bend == 0.0 && self.twist == 0.0
    }

    /// The twist angle at design height `z`.
    fn twist_at(&self, z: f64) -> f64 {
        let t = ((z - self.band.0) / (self.band.1 - self.band.0)).clamp(0.0, 1.0);
        self.twist * t * t * (3.0 - 2.0 * t)
    }

    /// The arc of the bend: its radius and the signed direction (+1 towards +X).
    fn arc(&self) -> (f64, f64) {
        let length = self.band.1 - self.band.0;
        (length / self.bend.abs(), self.bend.signum())
    }

    /// Where the design point `p` goes on a part moving with `segment`.
    pub fn forward(&self, segment: Segment, p: DVec3) -> DVec3 {
        match segment {
            Segment::Pelvis => p,
            Segment::Trunk => self.bend_forward(self.twist_forward(p)),
            Segment::Head => self.bend_forward(self.twist_forward(self.turn_head(p, 1.0))),
        }
    }

    /// The design point that goes to `p` on a part moving with `segment`.
    pub fn inverse(&self, segment: Segment, p: DVec3) -> DVec3 {
        match segment {
            Segment::Pelvis => p,
            Segment::Trunk => self.twist_inverse(self.bend_inverse(p)),
            Segment::Head => self.turn_head(self.twist_inverse(self.bend_inverse(p)), -1.0),
        }
    }

    fn twist_forward(&self, p: DVec3) -> DVec3 {
        if self.twist == 0.0 {
            return p;
        }
        DQuat::from_rotation_z(self.twist_at(p.z)) * p
    }

    fn twist_inverse(&self, p: DVec3) -> DVec3 {
        if self.twist == 0.0 {
            return p;
        }
        DQuat::from_rotation_z(-self.twist_at(p.z)) * p
    }

    fn turn_head(&self, p: DVec3, sign: f64) -> DVec3 {
        if self.head_turn == 0.0 {
            return p;
        }
        let axis = DVec3::new(self.neck_axis.0, self.neck_axis.1, 0.0);
        DQuat::from_rotation_z(sign * self.head_turn) * (p - axis) + axis
    }

    /// Barr's bend: the band's axis (x = 0) becomes an arc of radius `r` curving towards
    /// `side`; a point `x` off the axis stays `x` off it along the arc's normal.
    fn bend_forward(&self, p: DVec3) -> DVec3 {
        if self.bend.abs() < STRAIGHT || p.z <= self.band.0 {
            return p;
        }
        let (r, side) = self.arc();
        let (x, z0) = (side * p.x, self.band.0);
        let s = (p.z - z0).min(self.band.1 - z0);
        let angle = s / r;
        let (sin, cos) = angle.sin_cos();
        // Axis point, normal (towards +side) and tangent at arc length s.
        let (ax, az) = (r - r * cos, z0 + r * sin);
        let above = p.z - z0 - s;
        let (bx, bz) = (ax + x * cos + above * sin, az - x * sin + above * cos);
        DVec3::new(side * bx, p.y, bz)
    }

    fn bend_inverse(&self, p: DVec3) -> DVec3 {
        if self.bend.abs() < STRAIGHT || p.z <= self.band.0 {
            return p;
        }
        let (r, side) = self.arc();
        let (x, z0) = (side * p.x, self.band.0);
        let angle = (p.z - z0).atan2(r - x);
        let total = self.bend.abs();
        let (lx, lz) = if angle <= total {
            (r - (x - r).hypot(p.z - z0), z0 + angle * r)
        } else {
            // Above the band: undo the rigid move of the arc's end.
            let (sin, cos) = total.sin_cos();
            let (ax, az) = (r - r * cos, z0 + r * sin);
            let (dx, dz) = (x - ax, p.z - az);
            (dx * cos - dz * sin, self.band.1 + dx * sin + dz * cos)
        };
        DVec3::new(side * lx, p.y, lz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn posed() -> SpineWarp {
        SpineWarp {
            band: (1000.0, 1350.0),
            bend: 10f64.to_radians(),
            twist: -8f64.to_radians(),
            neck_axis: (0.0, 20.0),
            head_turn: 30f64.to_radians(),
        }
    }

    #[test]
    fn inverse_undoes_forward_everywhere() {
        for warp in [posed(), SpineWarp { bend: -0.1, ..posed() }, SpineWarp::upright()] {
            for i in 0..3000 {
                let f = i as f64;
                let p = DVec3::new(
                    (f * 37.7) % 1400.0 - 700.0,
                    (f * 13.3) % 400.0 - 200.0,
                    (f * 7.1) % 1800.0,
                );
                for segment in [Segment::Pelvis, Segment::Trunk, Segment::Head] {
                    let back = warp.inverse(segment, warp.forward(segment, p));
                    assert!(back.distance(p) < 1e-6, "{segment:?} {p}: {back}");
                }
            }
        }
    }

    #[test]
    fn the_spine_bends_towards_the_side_asked_and_keeps_its_length() {
        let warp = SpineWarp { twist: 0.0, ..posed() };
        let top = warp.forward(Segment::Trunk, DVec3::new(0.0, 0.0, 1350.0));
        assert!(top.x > 0.0 && top.z < 1350.0);
        // Chord of an arc of 350 mm bent by 10 degrees.
        let angle = 10f64.to_radians();
        let chord = 2.0 * (350.0 / angle) * (0.5 * angle).sin();
        assert!((top.distance(DVec3::new(0.0, 0.0, 1000.0)) - chord).abs() < 1e-3);
        // A shoulder 200 mm to the left moves down, the right one up: the shoulders tilt.
        let l = warp.forward(Segment::Trunk, DVec3::new(200.0, 0.0, 1400.0));
        let r = warp.forward(Segment::Trunk, DVec3::new(-200.0, 0.0, 1400.0));
        let tilt = ((r.z - l.z) / (l.x - r.x)).atan().to_degrees();
        assert!((tilt - 10.0).abs() < 1e-6, "{tilt}");
        // Below the band nothing moves.
        let hip = DVec3::new(150.0, 30.0, 900.0);
        assert_eq!(warp.forward(Segment::Trunk, hip), hip);
    }
}
