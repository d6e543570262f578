//! Tracking loops from level to level to find the landmarks and label every loop.

use super::armhole::{self, Armhole};
use super::{BodyRegions, LabelledSection, Landmarks, Region, RegionError, side};
use crate::mesh::Mesh;
use crate::slice::{Contour, Section, sections};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Index of the largest loop of `s` containing `p` (loops are sorted largest first).
fn loop_containing(s: &Section, p: DVec2) -> Option<usize> {
    s.loops.iter().position(|l| l.contains(p))
}

/// The loop of `s` that continues `prev` (a loop of the neighbouring level): the one holding
/// its centroid, or, where the centroid lies outside every loop (a loop pinched in the middle,
/// as the pelvis just above the crotch of a leg held out), the one holding most of its points.
fn continuing(s: &Section, prev: &Contour) -> Option<usize> {
    loop_containing(s, prev.centroid()).or_else(|| {
        let held = |k: usize| prev.points.iter().filter(|&&p| s.loops[k].contains(p)).count();
        (0..s.loops.len()).map(|k| (held(k), k)).filter(|&(n, _)| n > 0).max().map(|(_, k)| k)
    })
}

/// Follows a loop through `levels` (in the order given), starting from loop `start` of the
/// first, each level's loop [`continuing`] the previous one; stops where none does. Returns
/// (level index, loop index) pairs.
fn follow(
    sections: &[Section],
    levels: impl Iterator<Item = usize>,
    start: usize,
) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for i in levels {
        let k = match out.last() {
            None => Some(start),
            Some(&(j, prev)) => continuing(&sections[i], &sections[j].loops[prev]),
        };
        let Some(k) = k else { break };
        out.push((i, k));
    }
    out
}

/// The part of `body` between the heights `below` and `above`: all a bisection between two
/// tracking levels needs to cut.
fn between(body: &Mesh, below: f64, above: f64) -> Mesh {
    body.part(|tri| {
        let z = tri.map(|v| body.positions[v as usize].z);
        z[0].min(z[1]).min(z[2]) <= above && z[0].max(z[1]).max(z[2]) >= below
    })
}

/// The crotch between `below` (the legs apart, their loops around `legs`) and `above` (one
/// loop around both), by bisection to 0.1 mm, cutting only the part of the body between the
/// two heights.
fn refine_crotch(body: &Mesh, mut below: f64, mut above: f64, legs: [&Contour; 2]) -> f64 {
    let near = between(body, below, above);
    while above - below > 0.1 {
        let mid = 0.5 * (below + above);
        let s = &sections(&near, &[mid])[0];
        let [l, r] = legs.map(|c| continuing(s, c));
        if l.is_some() && l == r { above = mid } else { below = mid }
    }
    above
}

/// Where the legs are picked up, as a fraction of the height: the shins, below any hand
/// (fingertips hang at 0.38 of the stature or higher) and above the feet (the ankle is at
/// 0.04, the knee at 0.28: Drillis and Contini).
const SHIN_LEVEL: f64 = 0.15;

/// The armpit between `below` (the arm's loop `arm` apart from the torso's loop `torso`)
/// and `above` (joined), by bisection to 0.1 mm: the middle of the narrowest gap between the
/// arm and the torso just below where they join. The arm grows upward into the join, so a
/// level holds it apart as long as the torso's loop there does not overlap `arm`.
fn refine_armpit(
    body: &Mesh,
    mut below: f64,
    mut above: f64,
    arm: &Contour,
    torso: &Contour,
) -> DVec3 {
    let near = between(body, below, above);
    let torso_c = torso.centroid();
    let mut apart = (arm.clone(), torso.clone());
    while above - below > 0.1 {
        let mid = 0.5 * (below + above);
        let s = &sections(&near, &[mid])[0];
        let torso_here = loop_containing(s, torso_c).map(|t| &s.loops[t]);
        let arm_here = s.loops.iter().find(|l| overlaps(arm, l));
        match (torso_here, arm_here) {
            (Some(t), Some(a)) if !overlaps(arm, t) => {
                apart = (a.clone(), t.clone());
                below = mid;
            }
            _ => above = mid,
        }
    }
    let (p, q) = armhole::closest_points(&apart.0, &apart.1);
    (0.5 * (p + q)).extend(above)
}

/// How an arm joins the torso's loop going up.
#[derive(Debug, Clone, Copy)]
enum Join {
    /// The arm's own loop (this index, on the level below) merges into the torso's.
    Loop(usize),
    /// The torso's loop grows out sideways with no separate loop below: an arm held out.
    Outgrowth,
}

/// How much further a torso loop may reach sideways from one tracking level to the next
/// before an arm must have joined it (mm): the torso's side below the armpits widens by a few
/// millimetres per 5 mm level at most (its wall is far steeper than 3 in 1), while an arm
/// held out adds its whole length.
const ARM_JUMP_MM: f64 = 15.0;

/// How far loop `c` reaches to the side `sign` (+1 the subject's left, +X) of `centre` (mm).
fn reach(c: &Contour, sign: f64, centre: f64) -> f64 {
    c.points.iter().map(|p| sign * (p.x - centre)).fold(f64::NEG_INFINITY, f64::max)
}

/// The armpit of an arm that grows straight out of the torso's loop between `below` (the
/// torso's loop `torso` there, not yet joined) and `above`, by bisection to 0.1 mm: the
/// torso's outermost point on side `sign` at the highest level where its reach has not yet
/// jumped by [`ARM_JUMP_MM`] — the crease under the arm.
fn refine_outgrowth(
    body: &Mesh,
    mut below: f64,
    mut above: f64,
    torso: &Contour,
    sign: f64,
) -> DVec3 {
    let near = between(body, below, above);
    let (torso_c, centre) = (torso.centroid(), torso.bbox_centre().x);
    let limit = reach(torso, sign, centre) + ARM_JUMP_MM;
    let mut apart = torso.clone();
    while above - below > 0.1 {
        let mid = 0.5 * (below + above);
        let s = &sections(&near, &[mid])[0];
        match loop_containing(s, torso_c).map(|t| &s.loops[t]) {
            Some(t) if reach(t, sign, centre) <= limit => {
                apart = t.clone();
                below = mid;
            }
            _ => above = mid,
        }
    }
    let side = |p: &&DVec2| sign * (p.x - centre);
    let outermost = apart.points.iter().max_by(|a, b| side(a).total_cmp(&side(b)));
    outermost.copied().unwrap_or(torso_c).extend(above)
}

/// Whether loop `a` overlaps loop `b` seen from above: a point of `a` lies inside `b`.
fn overlaps(a: &Contour, b: &Contour) -> bool {
    a.points.iter().any(|&p| b.contains(p))
}

/// Tracks loops through `sections`, the body's sections every `step` mm from `floor` (at
/// `floor + step * (i + 0.5)`) over its `height`.
pub(super) fn track(
    body: &Mesh,
    step: f64,
    floor: f64,
    height: f64,
    sections: Vec<Section>,
) -> Result<BodyRegions, RegionError> {
    let n = sections.len();
    let z_of = |i: usize| floor + step * (i as f64 + 0.5);

    let seed = ((0.6 * height / step) as usize).min(n - 1);
    if sections[seed].loops.is_empty() {
        return Err(RegionError::NoTorso { z: z_of(seed) });
    }
    let up = follow(&sections, seed..n, 0);

    // Legs, from their ends: the two largest loops at the shins (below any hand, above the
    // feet), followed up until both land in one loop (the crotch: where the legs part) and
    // down to the floor.
    let shin = ((SHIN_LEVEL * height / step) as usize).min(n - 1);
    let shins = &sections[shin].loops;
    if shins.len() < 2 {
        return Err(RegionError::NoLegs { z: z_of(shin), loops: shins.len() });
    }
    let (left_k, right_k) =
        if shins[0].centroid().x > shins[1].centroid().x { (0, 1) } else { (1, 0) };
    let mut leg: Vec<[Option<usize>; 2]> = vec![[None, None]; n];
    let mut apart = [&shins[left_k], &shins[right_k]];
    let mut crotch_i = None;
    for i in shin..n {
        let found = if i == shin {
            [Some(left_k), Some(right_k)]
        } else {
            apart.map(|c| continuing(&sections[i], c))
        };
        match found {
            [Some(l), Some(r)] if l == r => {
                crotch_i = Some(i);
                break;
            }
            [Some(l), Some(r)] => {
                leg[i] = [Some(l), Some(r)];
                apart = [&sections[i].loops[l], &sections[i].loops[r]];
            }
            _ => break,
        }
    }
    let Some(crotch_i) = crotch_i.filter(|&i| i <= seed) else {
        return Err(RegionError::NoCrotch);
    };
    for (s, k) in [(0, left_k), (1, right_k)] {
        for (i, k) in follow(&sections, (0..=shin).rev(), k) {
            leg[i][s] = Some(k);
        }
    }
    let crotch = refine_crotch(body, z_of(crotch_i - 1), z_of(crotch_i), apart);
    let down = follow(&sections, (crotch_i..=seed).rev(), 0);
    let mut torso: Vec<Option<usize>> = vec![None; n];
    for &(i, k) in up.iter().chain(&down) {
        torso[i] = Some(k);
    }

    // Armpits: going up from the seed, the first level where the torso's loop takes in an arm
    // on that side: a loop beside it joins it (a hanging or A-posed arm at once, a raised
    // arm's underside as a thin sliver), or the loop reaches out at once much further than the
    // torso's side could (an arm held out horizontally grows straight out of it, with no
    // separate loop below).
    let joining = |sign: f64| {
        up.windows(2).find_map(|w| {
            let ((i, t), (j, t_next)) = (w[0], w[1]);
            let torso_here = &sections[i].loops[t];
            let centre = torso_here.bbox_centre().x;
            let next = &sections[j].loops[t_next];
            let mut beside = (0..sections[i].loops.len())
                .filter(|&k| k != t)
                .filter(|&k| sign * (sections[i].loops[k].centroid().x - centre) > 0.0);
            let arm_loop_here = beside.clone().next().is_some();
            let joined = beside.find(|&k| overlaps(&sections[i].loops[k], next)).map(Join::Loop);
            // An arm whose own loop is still beside the torso joins as that loop (its blend may
            // widen the torso's loop first); only an arm with none below grows out.
            let grown = !arm_loop_here
                && reach(next, sign, centre) - reach(torso_here, sign, centre) > ARM_JUMP_MM;
            joined.or(grown.then_some(Join::Outgrowth)).map(|how| (i, t, how))
        })
    };
    let (Some(left), Some(right)) = (joining(1.0), joining(-1.0)) else {
        let side = if joining(1.0).is_none() { "left" } else { "right" };
        return Err(RegionError::NoArm { side });
    };
    // The centre line: the torso's bounding-box centre just below the lower armpit.
    let (i, t, _) = if left.0 <= right.0 { left } else { right };
    let centre_x = sections[i].loops[t].bbox_centre().x;
    let armpit_point = |(i, t, how): (usize, usize, Join), sign: f64| {
        let torso_loop = &sections[i].loops[t];
        match how {
            Join::Loop(k) => {
                refine_armpit(body, z_of(i), z_of(i + 1), &sections[i].loops[k], torso_loop)
            }
            Join::Outgrowth => refine_outgrowth(body, z_of(i), z_of(i + 1), torso_loop, sign),
        }
    };
    let (left_pit, right_pit) = (armpit_point(left, 1.0), armpit_point(right, -1.0));
    let (left_armpit, right_armpit) = (left_pit.z, right_pit.z);

    // Neck: the narrowest torso level between the armpits and the head's widest level.
    let armpit_z = left_armpit.max(right_armpit);
    let head_level = floor + 0.87 * height;
    let girths: Vec<(usize, f64)> = up
        .par_iter()
        .filter(|&&(i, _)| z_of(i) > armpit_z || z_of(i) >= head_level)
        .map(|&(i, k)| (i, sections[i].loops[k].tape_girth()))
        .collect();
    let head_widest =
        girths.iter().filter(|&&(i, _)| z_of(i) >= head_level).max_by(|a, b| a.1.total_cmp(&b.1));
    let neck = girths
        .iter()
        .filter(|&&(i, _)| z_of(i) > armpit_z && head_widest.is_none_or(|h| i < h.0))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(armpit_z + 0.5 * (floor + height - armpit_z), |&(i, _)| z_of(i));

    // Ankle: the narrowest left-leg level between 3% and 15% of the height.
    let ankle = (0..crotch_i)
        .into_par_iter()
        .filter(|&i| (0.03..=0.15).contains(&((z_of(i) - floor) / height)))
        .filter_map(|i| leg[i][0].map(|k| (i, sections[i].loops[k].tape_girth())))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map_or(floor + 0.08 * height, |(i, _)| z_of(i));

    // Armholes: through each armpit and its shoulder point, facing sideways.
    let armhole = |pit: DVec3, sign: f64, name: &'static str| {
        let shoulder = armhole::shoulder_point(body, sign, centre_x, pit, neck)
            .ok_or(RegionError::NoArm { side: name })?;
        Ok(Armhole::through(pit, shoulder, DVec3::NEG_Y, sign))
    };
    let left_armhole = armhole(left_pit, 1.0, "left")?;
    let right_armhole = armhole(right_pit, -1.0, "right")?;

    let landmarks = Landmarks {
        height,
        crotch,
        ankle,
        left_armpit,
        right_armpit,
        neck,
        centre_x,
        left_armhole,
        right_armhole,
    };

    let levels = sections
        .into_iter()
        .enumerate()
        .map(|(i, section)| {
            let z = z_of(i);
            let head_loop = torso[i].filter(|_| z >= neck).map(|k| &section.loops[k]);
            let labels = (0..section.loops.len())
                .map(|k| {
                    let c = section.loops[k].centroid();
                    if torso[i] == Some(k) {
                        if z >= neck { Region::Head } else { Region::Torso }
                    } else if leg[i][0] == Some(k) {
                        Region::LeftLeg
                    } else if leg[i][1] == Some(k) {
                        Region::RightLeg
                    } else if z >= neck || head_loop.is_some_and(|h| h.contains(c)) {
                        Region::Head
                    } else {
                        side(c.x - centre_x, Region::LeftArm, Region::RightArm)
                    }
                })
                .collect();
            LabelledSection { section, labels }
        })
        .collect();
    Ok(BodyRegions { landmarks, labelling: super::Labelling::Tracked { step, levels } })
}
