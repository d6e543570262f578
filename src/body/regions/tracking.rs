//! Tracking loops from level to level to find the landmarks and label every loop.

use super::armhole::{self, Armhole};
use super::contact::{Contact, Neck, NeckGauge};
use super::{BISECTION_MM, BodyRegions, LabelledSection, Landmarks, Region, RegionError, side};
use crate::body::mesh::Mesh;
use crate::body::slice::{Contour, Section, sections};
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
        let held = |k: usize| s.loops[k].count_inside(&prev.points);
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

/// Whether triangle `tri` of `body` reaches from `below` to `above` or across them: the
/// triangles a bisection between two tracking levels needs to cut.
fn spans(body: &Mesh, tri: [u32; 3], below: f64, above: f64) -> bool {
    let z = tri.map(|v| body.positions[v as usize].z);
    z[0].min(z[1]).min(z[2]) <= above && z[0].max(z[1]).max(z[2]) >= below
}

/// A few bits for each vertex of `body` from its height (`bits(z)`), in one pass over the
/// positions in order: a pass over every triangle then tests its corners by three lookups in
/// this table of a byte a vertex, not by three reads of scattered 24-byte positions.
fn height_bits(body: &Mesh, bits: impl Fn(f64) -> u8 + Sync) -> Vec<u8> {
    body.positions.par_iter().map(|p| bits(p.z)).collect()
}

/// The [`height_bits`] of triangle `tri`'s corners, or-ed.
fn corner_bits(bits: &[u8], tri: [u32; 3]) -> u8 {
    tri.iter().fold(0, |all, &v| all | bits[v as usize])
}

/// [`spans`] as [`height_bits`]: a triangle spans `below`..`above` when its corners' bits
/// or-ed are both of these (a corner at or under `above`, and one at or over `below`).
const SPAN_BITS: u8 = 0b11;

/// A vertex's bits for [`SPAN_BITS`].
fn span_bits(below: f64, above: f64) -> impl Fn(f64) -> u8 + Sync {
    move |z| u8::from(z <= above) | u8::from(z >= below) << 1
}

/// The triangles of a body reaching a height or higher (a corner at or above it), in order:
/// from the lower arm's join up, all that the armpits' bisections and the shoulders' searches
/// look at, found in one pass over the body instead of one per search.
struct Reaching<'a> {
    body: &'a Mesh,
    triangles: Vec<u32>,
}

impl<'a> Reaching<'a> {
    /// The triangles of `body` reaching `from`.
    fn new(body: &'a Mesh, from: f64) -> Reaching<'a> {
        let high = height_bits(body, |z| u8::from(z >= from));
        let reaches = |t: &u32| corner_bits(&high, body.triangles[*t as usize]) != 0;
        let triangles = (0..body.triangles.len() as u32).into_par_iter().filter(reaches).collect();
        Reaching { body, triangles }
    }

    /// The part of the body between the heights `below` and `above` (`below` no lower than the
    /// height these triangles reach, or the part misses triangles under it).
    fn between(&self, below: f64, above: f64) -> Mesh {
        let body = self.body;
        let tri = |&t: &u32| body.triangles[t as usize];
        let kept = self.triangles.par_iter().map(tri).filter(|&t| spans(body, t, below, above));
        body.part_of(kept.collect())
    }
}

/// The crotch between `below` (the legs apart, their loops around `legs`) and `above` (one
/// loop around both), by bisection to [`BISECTION_MM`], cutting only the part of the body
/// between the two heights.
fn refine_crotch(body: &Mesh, mut below: f64, mut above: f64, legs: [&Contour; 2]) -> f64 {
    let bits = height_bits(body, span_bits(below, above));
    let near = body.part(|tri| corner_bits(&bits, tri) == SPAN_BITS);
    while above - below > BISECTION_MM {
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
/// and `above` (joined), by bisection to [`BISECTION_MM`]: the middle of the narrowest gap
/// between the arm and the torso just below where they join. The arm grows upward into the
/// join, so a level holds it apart as long as the torso's loop there does not overlap `arm`.
/// Cuts only the triangles `upper` (reaching `below`).
fn refine_armpit(
    upper: &Reaching,
    mut below: f64,
    mut above: f64,
    arm: &Contour,
    torso: &Contour,
) -> DVec3 {
    let near = upper.between(below, above);
    let torso_c = torso.centroid();
    let mut apart = (arm.clone(), torso.clone());
    while above - below > BISECTION_MM {
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

/// The armpit of an arm that rests on the torso (see [`super::contact`]): going up the
/// torso's tracked loops `up` from the join (arm `arm` apart from the torso's loop on level
/// `join.level`, joined from `joined` mm), the first level where the neck between them has
/// opened, refined by bisection to [`BISECTION_MM`]; `None` when the neck is open on the first
/// joined level (an arm that leaves the torso at an angle: its armpit is where the loops join).
/// Cuts only the triangles `upper` (reaching the join's level).
fn top_of_contact(
    upper: &Reaching,
    levels: &[Section],
    grid: Grid,
    up: &[(usize, usize)],
    join: &ArmJoin,
    arm: &Contour,
    joined: f64,
) -> Option<(DVec3, Contact)> {
    let torso = &levels[join.level].loops[join.torso];
    let gauge = NeckGauge::between(torso, arm);
    let neck_of = |c: &Contour| gauge.neck(c);
    let above: Vec<&(usize, usize)> = up.iter().filter(|&&(i, _)| i > join.level).collect();
    let first_open =
        above.iter().position(|&&(i, k)| gauge.is_open(neck_of(&levels[i].loops[k])))?;
    if first_open == 0 {
        return None;
    }
    let (closed_level, closed_loop) = *above[first_open - 1];
    let mut closed: Neck = neck_of(&levels[closed_level].loops[closed_loop])?;
    let (mut below, mut top) = (grid.z(closed_level), grid.z(above[first_open].0));
    let near = upper.between(below, top);
    let centre = torso.centroid();
    while top - below > BISECTION_MM {
        let mid = 0.5 * (below + top);
        let s = &sections(&near, &[mid])[0];
        let neck = loop_containing(s, centre).and_then(|t| neck_of(&s.loops[t]));
        match neck.filter(|_| !gauge.is_open(neck)) {
            Some(n) => {
                closed = n;
                below = mid;
            }
            None => top = mid,
        }
    }
    Some((closed.centre.extend(top), gauge.contact(&closed, joined)))
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
/// torso's loop `torso` there, not yet joined) and `above`, by bisection to [`BISECTION_MM`]:
/// the torso's outermost point on side `sign` at the highest level where its reach has not
/// yet jumped by [`ARM_JUMP_MM`] — the crease under the arm. Cuts only the triangles `upper`
/// (reaching `below`).
fn refine_outgrowth(
    upper: &Reaching,
    mut below: f64,
    mut above: f64,
    torso: &Contour,
    sign: f64,
) -> DVec3 {
    let near = upper.between(below, above);
    let (torso_c, centre) = (torso.centroid(), torso.bbox_centre().x);
    let limit = reach(torso, sign, centre) + ARM_JUMP_MM;
    let mut apart = torso.clone();
    while above - below > BISECTION_MM {
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
    b.holds_any(&a.points)
}

/// Where the torso is picked up, as a fraction of the height: between the crotch (the hip
/// joint at 0.530 H) and the armpits (the chest at 0.720 H), Drillis and Contini.
const TORSO_SEED_LEVEL: f64 = 0.6;
/// The chin, as a fraction of the height (0.870 H, Drillis and Contini): the neck lies below
/// the head's widest level above it, and no arm joins the torso above it.
const CHIN_LEVEL: f64 = 0.87;
/// Where the ankle (the narrowest level of the leg near the floor) is looked for, as
/// fractions of the height: above the floor contact of the sole, up to the shins.
const ANKLE_BAND: (f64, f64) = (0.03, SHIN_LEVEL);
/// The ankle's height when no leg loop lies in [`ANKLE_BAND`], as a fraction of the height:
/// the narrowest part of the shank, above the malleolus (0.039 H, Drillis and Contini).
const ANKLE_FALLBACK: f64 = 0.08;

/// The tracking levels: level `i` at `floor + step * (i + 0.5)`.
#[derive(Debug, Clone, Copy)]
struct Grid {
    floor: f64,
    step: f64,
    height: f64,
    count: usize,
}

impl Grid {
    /// Height of level `i` (mm).
    fn z(&self, i: usize) -> f64 {
        self.floor + self.step * (i as f64 + 0.5)
    }

    /// The level at `fraction` of the body's height.
    fn at(&self, fraction: f64) -> usize {
        ((fraction * self.height / self.step) as usize).min(self.count - 1)
    }

    /// Whether level `i` lies between the fractions `band` of the height.
    fn within(&self, i: usize, band: (f64, f64)) -> bool {
        (band.0..=band.1).contains(&((self.z(i) - self.floor) / self.height))
    }
}

/// The legs, followed from the shins: each level's left and right leg loop, the first level
/// where they are one loop (the crotch), and their loops just below it.
struct Legs {
    loops: Vec<[Option<usize>; 2]>,
    crotch_level: usize,
    apart: [(usize, usize); 2],
}

/// The legs from their ends: the two largest loops at the shins (below any hand, above the
/// feet), followed up until both land in one loop (the crotch: where the legs part), which
/// must be at or below the torso's `seed` level, and down to the floor.
fn track_legs(sections: &[Section], grid: Grid, seed: usize) -> Result<Legs, RegionError> {
    let shin = grid.at(SHIN_LEVEL);
    let shins = &sections[shin].loops;
    if shins.len() < 2 {
        return Err(RegionError::NoLegs { z: grid.z(shin), loops: shins.len() });
    }
    let start = if shins[0].centroid().x > shins[1].centroid().x { [0, 1] } else { [1, 0] };
    let mut loops: Vec<[Option<usize>; 2]> = vec![[None, None]; grid.count];
    let mut apart = start.map(|k| (shin, k));
    let mut crotch_level = None;
    for i in shin + 1..grid.count {
        let found = apart.map(|(j, k)| continuing(&sections[i], &sections[j].loops[k]));
        match found {
            [Some(l), Some(r)] if l == r => {
                crotch_level = Some(i);
                break;
            }
            [Some(l), Some(r)] => {
                loops[i] = [Some(l), Some(r)];
                apart = [(i, l), (i, r)];
            }
            _ => break,
        }
    }
    let Some(crotch_level) = crotch_level.filter(|&i| i <= seed) else {
        return Err(RegionError::NoCrotch);
    };
    for (s, k) in start.into_iter().enumerate() {
        for (i, k) in follow(sections, (0..=shin).rev(), k) {
            loops[i][s] = Some(k);
        }
    }
    Ok(Legs { loops, crotch_level, apart })
}

/// Where an arm joins the torso going up: the level `level` below the join, the torso's loop
/// `torso` there, and how.
#[derive(Debug, Clone, Copy)]
struct ArmJoin {
    level: usize,
    torso: usize,
    how: Join,
}

/// Where the arm on side `sign` (+1 the subject's left) joins the torso's loops `up` (from
/// the seed upward, below the chin level `chin`): going up, the first level where the
/// torso's loop takes in an arm on that side. A loop beside it joins it (a hanging or A-posed
/// arm at once, a raised arm's underside as a thin sliver), or the loop reaches out at once
/// much further than the torso's side could (an arm held out horizontally grows straight out
/// of it, with no separate loop below).
fn arm_join(
    sections: &[Section],
    up: &[(usize, usize)],
    chin: usize,
    sign: f64,
) -> Option<ArmJoin> {
    let below_chin: Vec<(usize, usize)> =
        up.iter().take_while(|&&(i, _)| i < chin).copied().collect();
    below_chin.windows(2).find_map(|w| {
        let ((i, t), (j, t_next)) = (w[0], w[1]);
        let (here, next) = (&sections[i].loops[t], &sections[j].loops[t_next]);
        let centre = here.bbox_centre().x;
        let mut beside = (0..sections[i].loops.len())
            .filter(|&k| k != t)
            .filter(|&k| sign * (sections[i].loops[k].centroid().x - centre) > 0.0);
        let arm_loop_here = beside.clone().next().is_some();
        // Joined: the arm's loop overlaps the torso's next loop and is continued by it, not
        // by a loop of its own (an arm running close beside the torso, in front of the hip,
        // overlaps it seen from above without touching it).
        let joined = beside
            .find(|&k| {
                let arm = &sections[i].loops[k];
                overlaps(arm, next) && continuing(&sections[j], arm) == Some(t_next)
            })
            .map(Join::Loop);
        // An arm whose own loop is still beside the torso joins as that loop (its blend may
        // widen the torso's loop first); only an arm with none below grows out.
        let grown =
            !arm_loop_here && reach(next, sign, centre) - reach(here, sign, centre) > ARM_JUMP_MM;
        let how = joined.or(grown.then_some(Join::Outgrowth))?;
        Some(ArmJoin { level: i, torso: t, how })
    })
}

/// The neck: the narrowest torso level (of `up`) above the higher armpit `armpit_z` and below
/// the head's widest level above the chin.
fn neck_level(sections: &[Section], grid: Grid, up: &[(usize, usize)], armpit_z: f64) -> f64 {
    let chin = grid.floor + CHIN_LEVEL * grid.height;
    let girths: Vec<(usize, f64)> = up
        .par_iter()
        .filter(|&&(i, _)| grid.z(i) > armpit_z || grid.z(i) >= chin)
        .map(|&(i, k)| (i, sections[i].loops[k].tape_girth()))
        .collect();
    let head_widest =
        girths.iter().filter(|&&(i, _)| grid.z(i) >= chin).max_by(|a, b| a.1.total_cmp(&b.1));
    girths
        .iter()
        .filter(|&&(i, _)| grid.z(i) > armpit_z && head_widest.is_none_or(|h| i < h.0))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(armpit_z + 0.5 * (grid.floor + grid.height - armpit_z), |&(i, _)| grid.z(i))
}

/// The ankle: the narrowest left-leg level in [`ANKLE_BAND`].
fn ankle_level(sections: &[Section], grid: Grid, legs: &Legs) -> f64 {
    (0..legs.crotch_level)
        .into_par_iter()
        .filter(|&i| grid.within(i, ANKLE_BAND))
        .filter_map(|i| legs.loops[i][0].map(|k| (i, sections[i].loops[k].tape_girth())))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map_or(grid.floor + ANKLE_FALLBACK * grid.height, |(i, _)| grid.z(i))
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
    let grid = Grid { floor, step, height, count: sections.len() };
    let seed = grid.at(TORSO_SEED_LEVEL);
    if sections[seed].loops.is_empty() {
        return Err(RegionError::NoTorso { z: grid.z(seed) });
    }
    // The torso up from the seed beside the legs, the crotch and the torso down to it; then
    // each side's arm beside the other's: each is serial, level by level.
    let (up, lower) = rayon::join(
        || follow(&sections, seed..grid.count, 0),
        || {
            let legs = track_legs(&sections, grid, seed)?;
            let apart = legs.apart.map(|(i, k)| &sections[i].loops[k]);
            let (below, above) = (grid.z(legs.crotch_level - 1), grid.z(legs.crotch_level));
            let (crotch, down) = rayon::join(
                || refine_crotch(body, below, above, apart),
                || follow(&sections, (legs.crotch_level..=seed).rev(), 0),
            );
            Ok((legs, crotch, down))
        },
    );
    let (legs, crotch, down) = lower?;
    let mut torso: Vec<Option<usize>> = vec![None; grid.count];
    for &(i, k) in up.iter().chain(&down) {
        torso[i] = Some(k);
    }

    let chin = grid.at(CHIN_LEVEL);
    let arm = |sign: f64, side: &'static str| {
        arm_join(&sections, &up, chin, sign).ok_or(RegionError::NoArm {
            side,
            from: grid.z(seed),
            to: grid.z(chin),
        })
    };
    let (left, right) = rayon::join(|| arm(1.0, "left"), || arm(-1.0, "right"));
    let (left, right) = (left?, right?);
    // The centre line: the torso's bounding-box centre just below the lower armpit.
    let lower = if left.level <= right.level { left } else { right };
    let centre_x = sections[lower.level].loops[lower.torso].bbox_centre().x;
    let upper = Reaching::new(body, grid.z(lower.level));
    // Each armpit, and where its arm rests on the torso below it if it does.
    let armpit_point = |join: ArmJoin, sign: f64| {
        let (i, torso_loop) = (join.level, &sections[join.level].loops[join.torso]);
        match join.how {
            Join::Loop(k) => {
                let arm = &sections[i].loops[k];
                let pit = refine_armpit(&upper, grid.z(i), grid.z(i + 1), arm, torso_loop);
                match top_of_contact(&upper, &sections, grid, &up, &join, arm, pit.z) {
                    Some((top, contact)) => (top, Some(contact)),
                    None => (pit, None),
                }
            }
            Join::Outgrowth => {
                (refine_outgrowth(&upper, grid.z(i), grid.z(i + 1), torso_loop, sign), None)
            }
        }
    };
    let (left_pit, right_pit) =
        rayon::join(|| armpit_point(left, 1.0), || armpit_point(right, -1.0));
    // Armholes: through each armpit and its shoulder point, facing sideways; each shoulder
    // point looked for among the triangles near its side's search.
    let searches = [(left_pit.0, 1.0), (right_pit.0, -1.0)]
        .map(|(pit, sign)| armhole::ShoulderSearch::new(sign, centre_x, pit));
    let ((neck, ankle), near) = rayon::join(
        || {
            rayon::join(
                || neck_level(&sections, grid, &up, left_pit.0.z.max(right_pit.0.z)),
                || ankle_level(&sections, grid, &legs),
            )
        },
        || near_shoulders(&upper, &searches),
    );
    let armhole = |k: usize, (pit, contact): (DVec3, Option<Contact>), name: &'static str| {
        let shoulder = searches[k]
            .shoulder_point(body, &near[k], neck)
            .ok_or(RegionError::NoShoulder { side: name, armpit: pit.z })?;
        let plate = Armhole::through(pit, shoulder, DVec3::NEG_Y, searches[k].side());
        Ok(contact.map_or(plate, |c| plate.with_contact(c)))
    };
    let (left_armhole, right_armhole) =
        rayon::join(|| armhole(0, left_pit, "left"), || armhole(1, right_pit, "right"));
    let landmarks = Landmarks {
        height: floor + height,
        crotch,
        ankle,
        left_armpit: left_pit.0.z,
        right_armpit: right_pit.0.z,
        neck,
        centre_x,
        left_armhole: left_armhole?,
        right_armhole: right_armhole?,
    };
    let levels = label_levels(sections, grid, &torso, &legs, &landmarks);
    Ok(BodyRegions { landmarks, labelling: super::Labelling::Tracked { step, levels } })
}

/// The triangles of the body that [`armhole::ShoulderSearch::may_touch`] each of the two
/// searches, in the body's order, from one pass over the triangles `upper` (reaching below
/// both armpits: all that may touch).
fn near_shoulders(upper: &Reaching, searches: &[armhole::ShoulderSearch; 2]) -> [Vec<u32>; 2] {
    let (body, among) = (upper.body, &upper.triangles);
    crate::body::mesh::reduce::fold(
        among.len(),
        || [Vec::new(), Vec::new()],
        |mut near: [Vec<u32>; 2], i| {
            let c = body.corners(among[i] as usize);
            for (list, search) in near.iter_mut().zip(searches) {
                if search.may_touch(&c) {
                    list.push(among[i]);
                }
            }
            near
        },
        |[mut left, mut right], [later_left, later_right]| {
            left.extend(later_left);
            right.extend(later_right);
            [left, right]
        },
    )
}

/// Every tracked level's loops labelled: the tracked torso (at and above the neck, head) and
/// legs; other loops above the neck or inside the head's loop, head; the rest, arms by side.
fn label_levels(
    sections: Vec<Section>,
    grid: Grid,
    torso: &[Option<usize>],
    legs: &Legs,
    landmarks: &Landmarks,
) -> Vec<LabelledSection> {
    let (neck, centre_x) = (landmarks.neck, landmarks.centre_x);
    sections
        .into_par_iter()
        .enumerate()
        .map(|(i, section)| {
            let z = grid.z(i);
            let head_loop = torso[i].filter(|_| z >= neck).map(|k| &section.loops[k]);
            let labels = (0..section.loops.len())
                .map(|k| {
                    let c = section.loops[k].centroid();
                    if torso[i] == Some(k) {
                        if z >= neck { Region::Head } else { Region::Torso }
                    } else if legs.loops[i][0] == Some(k) {
                        Region::LeftLeg
                    } else if legs.loops[i][1] == Some(k) {
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
        .collect()
}
