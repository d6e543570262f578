//! Where the scan's stance, not the body, sets a measurement (issue 33): `measure` and
//! `symmetrize` take a scan as it stands, so a trunk leaning sideways or a shoulder raised moves
//! the levels and widths found from the armpits and shoulder points. A warning says so and
//! names `reconstruct`, which re-poses the scan symmetric first.

use crate::body::regions::Landmarks;

/// How far apart in height the two armpits, or the two shoulder points, of a symmetric stance
/// may be found (mm): a found armpit lies within 10 mm of the body's
/// (`tests/segmentation_stances.rs`), so two of them up to about 15 mm apart on an upright,
/// symmetric body; the slightly asymmetric stances of both test populations put them 20-40 mm
/// apart.
pub const LEVEL_DIFFERENCE_MM: f64 = 15.0;

/// The warnings for a body whose `landmarks` show an asymmetric stance, naming the
/// measurements the stance changes.
pub fn warnings(landmarks: &Landmarks) -> Vec<String> {
    let m = landmarks;
    let shoulders = (m.left_armhole.shoulder_point.z, m.right_armhole.shoulder_point.z);
    let pairs = [
        (
            "armpits",
            (m.left_armpit, m.right_armpit),
            "the chest and bust levels (below the lower armpit), across back and across front",
        ),
        ("shoulder points", shoulders, "the shoulder slopes, shoulder width and across shoulder"),
    ];
    pairs
        .into_iter()
        .filter(|(_, (l, r), _)| (l - r).abs() > LEVEL_DIFFERENCE_MM)
        .map(|(what, (l, r), changed)| {
            format!(
                "the {what} stand {:.0} mm apart in height (left {l:.0}, right {r:.0} mm): the \
                 trunk leans or a shoulder is raised, and {changed} follow the pose, not the \
                 body; `dressform reconstruct` re-poses the scan symmetric first",
                (l - r).abs()
            )
        })
        .collect()
}
