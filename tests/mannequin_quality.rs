//! A mannequin a tailor would accept, on every kind of body we have: the demo customer (scanned
//! with a scanner's artifacts), standing symmetrically and as `dressform demo` poses it, 20
//! random customers of the sim generator, its asymmetric example and the MakeHuman base body.
//! Each test prints its numbers.
//!
//! Set `DRESSFORM_LOOK=<dir>` to also write every body's input and mannequin there as OBJ, to
//! render them (`python3 ../shared/tools/look.py out.png <dir>/<name>-mannequin.obj`).

use crate::common;

use capture_sim::{Artifacts, BodyParams, Pose, SyntheticBody, capture, generate};
use common::quality::{
    PlateRim, creases, edge_creases, largest_crease, near_horizontal_area, plate_rim,
    self_intersecting_pairs, silhouette_top, width_jump,
};
use common::{largest_mirror_gap, makehuman, surface_mesh as mesh_of};
use dressform::body::mesh::{Mesh, smooth::DEFAULT_PASSES};
use dressform::body::regions::Region;
use dressform::body::scan::{self, Scan, format::Format, frame::FrameOptions};
use dressform::body::segmented_body::SegmentedBody;
use dressform::body::slice::Contour;
use dressform::pose::body_model::BodyModel;
use dressform::pose::makehuman::{MakeHuman, Pose as MhPose};
use dressform::run::pipeline::{Symmetrized, symmetrize};
use dressform::run::reconstruct::{ReconstructOptions, reconstruct};
use dressform::shape::mannequin::{Layer, LegStance, Mannequin, MannequinOptions};
use glam::DVec3;
use rayon::prelude::*;
use std::path::Path;

/// A body to test: its name, the scan, and for the generator's bodies in an A-pose the two
/// acromion points (canonical frame), which end the shoulder line.
struct Case {
    name: String,
    scan: Scan,
    acromions: Option<[DVec3; 2]>,
}

/// The generator's acromion points of `body` in the canonical frame of `scan`.
fn acromions(body: &SyntheticBody, scan: &Scan) -> Option<[DVec3; 2]> {
    let sides = [&body.truth.landmarks.left, &body.truth.landmarks.right];
    Some(sides.map(|s| scan.frame.to_canonical(DVec3::from_array(s.acromion))))
}

fn generated(name: String, params: &BodyParams) -> Case {
    let body = generate(params).unwrap();
    let scan = scan::from_mesh(mesh_of(&body.surface), Path::new(&name), &FrameOptions::default())
        .unwrap();
    Case { acromions: acromions(&body, &scan), name, scan }
}

/// The demo's customer, scanned as the demo scans it, denoised as the commands do.
fn demo_customer() -> Case {
    scanned_as_the_demo_does(&BodyParams::default())
}

/// The body of `params`, scanned as the demo scans it, denoised as the commands do.
fn scanned_as_the_demo_does(params: &BodyParams) -> Case {
    let body = generate(params).unwrap();
    let raw = capture(&body, &Artifacts::typical_scanner(0));
    let mut scan =
        scan::from_mesh(mesh_of(&raw), Path::new("demo"), &FrameOptions::default()).unwrap();
    scan.body.taubin_smooth(DEFAULT_PASSES);
    Case { acromions: acromions(&body, &scan), name: "demo".into(), scan }
}

/// The asymmetric example; its left arm, raised level with the shoulder, hides the shoulder
/// line in the front view, so that is not compared.
fn asymmetric() -> Case {
    let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
    Case { acromions: None, ..generated("asymmetric".into(), &params) }
}

/// The customer `dressform demo` scans: the demo's customer with the left arm
/// [`ARM_FURTHER_OUT_DEG`] further out than the right, scanned and denoised as the demo does.
/// Its armpits are about 22 mm apart (the left 1280, the right 1258 mm).
fn arm_out() -> Case {
    let mut params = BodyParams::default();
    params.pose.left_arm.abduction_deg += ARM_FURTHER_OUT_DEG;
    Case { name: "arm-out".into(), ..scanned_as_the_demo_does(&params) }
}

/// How much further out `dressform demo`'s customer holds the left arm (degrees), as the
/// demo poses it (`cli::demo::ARM_FURTHER_OUT_DEG`).
const ARM_FURTHER_OUT_DEG: f64 = 15.0;

fn makehuman_base() -> Option<Case> {
    let dir = makehuman()?;
    let scan = scan::load(&dir.join("base.obj"), &FrameOptions::default()).unwrap();
    Some(Case { name: "makehuman".into(), scan, acromions: None })
}

/// What one mannequin measures.
#[derive(Debug)]
struct Report {
    name: String,
    /// The width jump below the shoulder points: (mm, height).
    width_jump: (f64, f64),
    /// The most a torso layer under the mannequin's armpits reaches beyond the body's torso
    /// under its own armpits: (mm, its height; see [`underarm_excess`]).
    underarm_excess: (f64, f64),
    self_intersections: usize,
    /// Near-horizontal faces between the crotch and 50 mm above it: (total, largest), mm².
    crotch_ledge: (f64, f64),
    /// The same on the input body (its arms left out): the body's own saddle at the crotch.
    body_crotch_ledge: f64,
    /// Mannequin crotch height minus the body's (mm).
    crotch_change: f64,
    /// The largest crease (degrees) where the legs join the torso, across the thighs and hips,
    /// and around it (see [`crotch_creases`]).
    seam_crease: (f64, f64),
    /// The median crease (degrees) along the rings on either side of the join, and along the
    /// other rings near it (see [`join_line`]).
    join_line: (f64, f64),
    /// The sharpest ring of the thighs within [`THIGH_TOP_MM`] below the crotch and the
    /// sharpest further down (degrees; see [`thigh_creases`]).
    thigh_crease: (f64, f64),
    /// The 90th percentile of the creases along the legs' top ring (degrees; see
    /// [`join_ticks`]).
    join_ticks: f64,
    mirror_gap: f64,
    /// The largest change of a torso layer's tape girth below the shoulder points (where the
    /// mesh's rings are the horizontal layers), measured on the mesh (mm).
    torso_girth_change: f64,
    /// The same for the horizontal sections of the mesh at the layers' heights above the
    /// shoulder points (mm): there the mesh's rings are bent and the sections are symmetrized
    /// along them, not along the horizontal.
    cap_girth_change: f64,
    /// How far below the lower shoulder point the mesh's rings start to bend (mm; at most 0).
    bent_below_shoulders: f64,
    /// The width jump (as [`width_jump`]) above the shoulder points, of the input body's torso
    /// (its arms cut off at the armholes) and of the mannequin (mm): how far the body itself
    /// is from smooth there.
    shoulder_jump: (f64, f64),
    /// The largest difference between a torso layer's reported tape girth and its girth on
    /// the mesh, below the shoulder cap (mm).
    recorded_girth_error: f64,
    /// Abduction of the input's left leg, of its mirrored right leg, and of the mannequin's
    /// legs (degrees).
    leg_deg: [f64; 3],
    /// The mannequin's legs' lean forward (degrees; see [`flexion_deg`]).
    leg_flexion_deg: f64,
    /// How the mannequin's legs stand.
    legs: LegStance,
    /// The smallest gap between the two legs' layers (mm).
    leg_gap: f64,
    /// The largest height difference between the mannequin's shoulder line and the body's
    /// (mm), where the shoulders are known.
    shoulder_line: Option<f64>,
    /// The left arm plate's rim: its turning and its flat bottom are checked.
    rim: Option<PlateRim>,
}

/// How far above the crotch the ledge check looks (mm), from the issue.
const CROTCH_BAND_MM: f64 = 50.0;
/// "Near-horizontal": a face normal within this angle of vertical (degrees), from the issue.
const HORIZONTAL_TILT_DEG: f64 = 10.0;
/// The spacing of the slices the width jump compares (mm), from the definition.
const SLICE_STEP_MM: f64 = 2.0;
/// The largest width jump allowed (mm), from the issue: a smooth body stays under it.
const WIDTH_JUMP_MM: f64 = 15.0;
/// How far the mannequin's shoulder line may be from the body's (mm), from the issue.
const SHOULDER_LINE_MM: f64 = 5.0;
/// How close the mannequin's leg direction is to the mean of the input's (degrees), when its
/// legs stand as the customer stood.
const LEG_STANCE_DEG: f64 = 0.5;
/// How close to vertical the mannequin's legs' axes are (degrees, sideways and front to back),
/// when they stand straight: issue 35's acceptance.
const STRAIGHT_LEG_DEG: f64 = 1.0;
/// The most the left arm plate's rim may turn in all (degrees): a convex curve turns 360, and
/// each step of a staircase (one per layer, 15-20 layers up each side) adds about 180; the
/// rims, one curve, turn 360-454 degrees on the generator's bodies, 384 on the asymmetric
/// example, 421 on MakeHuman and 467 on the demo's noisy scan.
const RIM_TURNING_DEG: f64 = 560.0;
/// The longest flat bottom the left arm plate's rim may have (mm; see [`PlateRim`]). Before
/// the rim's lower edge was drawn round it was the first ring's whole chord on the plate:
/// 9.1-48.0 mm on the generator's bodies, 31.0 on the demo customer, 31.6 on the asymmetric
/// example, 25.6 on MakeHuman (every body over this). Now the lowest ring keeps 6 mm of its
/// chord (`arm_plates::BOTTOM_HALF_MM`), stretched with its ring back to its girth: 6.0-6.8
/// mm on all 25 bodies. The limit leaves a third of the kept chord for that stretch.
const RIM_FLAT_BOTTOM_MM: f64 = 8.0;
/// The largest near-horizontal face allowed in that band (mm²: 1 cm², from the issue).
const LEDGE_FACE_MM2: f64 = 100.0;

/// The sharpest crease allowed where the legs join the torso, away from the plane (degrees):
/// the layers around the join crease up to 45 degrees on the bodies tested (random-4) and the
/// join stays below 53 (it folded up to 165 degrees when it was matched by arc length: a line
/// across the thighs in every shaded picture).
const SEAM_CREASE_DEG: f64 = 60.0;

/// How far the crease check stays from the symmetry plane (mm): at the crotch itself the
/// inner thighs meet in a saddle that is sharp on every body.
const CREASE_BESIDE_PLANE_MM: f64 = 30.0;

/// The largest crease of `mesh` (degrees) across the triangles that span the crotch height
/// (where the legs' top rings join the torso), and the largest among the other triangles
/// within [`CROTCH_BAND_MM`] of it; both on the thighs and hips, away from the plane.
fn crotch_creases(mesh: &Mesh, axis: f64, crotch: f64) -> (f64, f64) {
    let away = |c: [DVec3; 3]| c.iter().all(|p| (p.x - axis).abs() > CREASE_BESIDE_PLANE_MM);
    let near = |c: [DVec3; 3]| c.iter().all(|p| (p.z - crotch).abs() < CROTCH_BAND_MM);
    let spans = |c: [DVec3; 3]| {
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.z), hi.max(p.z)));
        lo <= crotch && crotch <= hi
    };
    let counted = |a, b| away(a) && away(b) && near(a) && near(b);
    (
        largest_crease(mesh, |a, b| counted(a, b) && (spans(a) || spans(b))),
        largest_crease(mesh, |a, b| counted(a, b) && !spans(a) && !spans(b)),
    )
}

/// How much more the rings on either side of the crotch join may crease, in the median, than
/// the rings near them (degrees): the join stood upright where the thigh and the hip slope
/// inward together, a 12-degree crease along both its rings on a MakeHuman body, shaded as a
/// line across the thighs.
const JOIN_LINE_DEG: f64 = 3.0;

/// A ring lies this close to the crotch height on either side of the join (mm): the legs'
/// top ring and the lowest torso ring are 1 mm from it.
const JOIN_RINGS_MM: f64 = 1.5;

/// The median crease (degrees) along the edges of the rings next to the crotch join (within
/// [`JOIN_RINGS_MM`] of the crotch height), and along the other rings within
/// [`CROTCH_BAND_MM`] of it; both away from the plane.
fn join_line(mesh: &Mesh, axis: f64, crotch: f64) -> (f64, f64) {
    let away = |c: &[DVec3]| c.iter().all(|p| (p.x - axis).abs() > CREASE_BESIDE_PLANE_MM);
    let on_ring = |e: [DVec3; 2], near: bool| {
        let dz = (e[0].z - crotch).abs();
        e[0].z == e[1].z && dz < CROTCH_BAND_MM && (dz < JOIN_RINGS_MM) == near
    };
    let median = |near: bool| {
        let mut c = creases(mesh, |a, b, e| away(&a) && away(&b) && on_ring(e, near));
        c.sort_by(f64::total_cmp);
        c.get(c.len() / 2).copied().unwrap_or(f64::NAN)
    };
    (median(true), median(false))
}

/// The band below the crotch where the thighs meet the hips (mm): the leg layers (13-14 mm
/// apart at the paper's 50) met the torso's (6-7 mm apart) there with a kink, a line across
/// the thighs in a shaded picture of a reconstructed body.
const THIGH_TOP_MM: f64 = 60.0;
/// The rings the thighs' top is compared with: from [`THIGH_REGULAR_MM`] down to this far below
/// the crotch (mm).
const THIGH_BELOW_MM: f64 = 250.0;
/// Where the legs' mesh rings are their layers alone again (mm below the crotch).
const THIGH_REGULAR_MM: f64 = 100.0;
/// Sectors around each leg ring: a kink across the back of the thigh alone (a quarter of the
/// ring) shows in its sector's median, not in the whole ring's.
const THIGH_SECTORS: usize = 8;
/// A sector's median counts where it has at least this many ring edges.
const SECTOR_EDGES: usize = 5;

/// How much sharper the thighs' sharpest ring near the crotch may be than the sharpest further
/// down (degrees). With the leg layers alone (13-15 mm apart) it was 8.0-11.5 degrees sharper
/// on the generator's bodies (the gluteal fold's turn on single rings: a shaded line across
/// the back of the thighs) and 7.8 on the demo's reconstructed customer; with the mesh's finer
/// rings there, 4.0-6.0 and 4.8, and 5.0-7.4 on the MakeHuman bodies, where the body's own
/// coarse facets show; with the thighs also leaving the hips at the hips' slope, 4.0-6.7,
/// 5.0-5.1 and 6.1-7.3.
const THIGH_CREASE_DEG: f64 = 8.0;

/// The sharpest ring of the left thigh between `top` and `bottom` mm below the crotch: the
/// largest median crease (degrees) along the edges of one ring (horizontal edges at one
/// height) in one of [`THIGH_SECTORS`] sectors around the leg's centre, away from the plane.
fn sharpest_thigh_ring(mesh: &Mesh, axis: f64, crotch: f64, top: f64, bottom: f64) -> f64 {
    let beside = |c: &[DVec3]| c.iter().all(|p| p.x - axis > CREASE_BESIDE_PLANE_MM);
    let in_band = |e: [DVec3; 2]| {
        let below = crotch - e[0].z;
        e[0].z == e[1].z && below >= top && below < bottom
    };
    let edges = edge_creases(mesh, |a, b, e| beside(&a) && beside(&b) && in_band(e));
    let mut rings: std::collections::BTreeMap<u64, Vec<(DVec3, f64)>> = Default::default();
    for (e, deg) in edges {
        rings.entry(e[0].z.to_bits()).or_default().push((0.5 * (e[0] + e[1]), deg));
    }
    let mut sharpest = 0.0_f64;
    for ring in rings.values() {
        let centre = ring.iter().map(|(m, _)| *m).sum::<DVec3>() / ring.len() as f64;
        let mut sectors = vec![Vec::new(); THIGH_SECTORS];
        for (m, deg) in ring {
            let turn = (m.y - centre.y).atan2(m.x - centre.x).rem_euclid(std::f64::consts::TAU);
            let k = (turn / std::f64::consts::TAU * THIGH_SECTORS as f64) as usize;
            sectors[k.min(THIGH_SECTORS - 1)].push(*deg);
        }
        for mut s in sectors.into_iter().filter(|s| s.len() >= SECTOR_EDGES) {
            s.sort_by(f64::total_cmp);
            sharpest = sharpest.max(s[s.len() / 2]);
        }
    }
    sharpest
}

/// The sharpest ring of the left thigh (see [`sharpest_thigh_ring`]) from just below the crotch
/// join (its own rings are [`join_line`]'s) down to [`THIGH_TOP_MM`] below the crotch, and
/// from [`THIGH_REGULAR_MM`] down to [`THIGH_BELOW_MM`].
fn thigh_creases(mesh: &Mesh, axis: f64, crotch: f64) -> (f64, f64) {
    (
        sharpest_thigh_ring(mesh, axis, crotch, JOIN_RINGS_MM, THIGH_TOP_MM),
        sharpest_thigh_ring(mesh, axis, crotch, THIGH_REGULAR_MM, THIGH_BELOW_MM),
    )
}

/// The crease along the legs' top ring that one edge in ten may exceed (degrees). Where the
/// thighs met the hips keeping their own slope, the back of that ring creased 6-15 degrees (a
/// light line across the thighs at the crotch in a shaded picture); its 90th percentile was
/// 4.5 on the asymmetric example, 8.7 on the demo's customer (both ways), 11.1 on the
/// MakeHuman base and 12.0 on the posed MakeHuman body. With the thighs leaving the hips at the
/// hips' slope: 1.4-3.3 on the generator's 20 random bodies, 3.1, 2.9-3.0, 8.3 and 9.0. What is
/// left on the MakeHuman bodies is not explained yet.
const JOIN_TICKS_DEG: f64 = 10.0;

/// The share of the legs' top ring's edges [`JOIN_TICKS_DEG`] is read at.
const JOIN_TICKS_SHARE: f64 = 0.9;

/// The creases (degrees) along the edges of the legs' top rings (within [`JOIN_RINGS_MM`]
/// below the crotch height, where they join the torso), away from the plane: the value
/// [`JOIN_TICKS_SHARE`] of them stay under.
fn join_ticks(mesh: &Mesh, axis: f64, crotch: f64) -> f64 {
    let away = |c: &[DVec3]| c.iter().all(|p| (p.x - axis).abs() > CREASE_BESIDE_PLANE_MM);
    let on_top_ring =
        |e: [DVec3; 2]| e[0].z == e[1].z && (0.0..JOIN_RINGS_MM).contains(&(crotch - e[0].z));
    let mut c = creases(mesh, |a, b, e| away(&a) && away(&b) && on_top_ring(e));
    c.sort_by(f64::total_cmp);
    let k = ((c.len() as f64 * JOIN_TICKS_SHARE) as usize).min(c.len().saturating_sub(1));
    c.get(k).copied().unwrap_or(f64::NAN)
}

/// The lowest point of `mesh` on the plane x = `axis`: the mannequin's crotch.
fn crotch_on_plane(mesh: &Mesh, axis: f64) -> f64 {
    (0..mesh.triangles.len())
        .flat_map(|t| {
            let c = mesh.corners(t);
            (0..3).filter_map(move |i| {
                let (a, b) = (c[i], c[(i + 1) % 3]);
                ((a.x - axis) * (b.x - axis) <= 0.0 && a.x != b.x)
                    .then(|| a.z + (b.z - a.z) * (axis - a.x) / (b.x - a.x))
            })
        })
        .fold(f64::INFINITY, f64::min)
}

/// How far below the mannequin's armpits [`underarm_excess`] looks (mm): the underarm's
/// hollow, and a layer's spacing more.
const UNDERARM_DEPTH_MM: f64 = 30.0;

/// The most a torso layer under the mannequin's armpits may reach beyond the body's torso
/// under its own armpits (mm; see [`underarm_excess`]). A layer between two armpits at
/// different heights keeps its section's girth (eq. 8), which holds one side's underarm, so it
/// swells a little all round: 3.1 mm on arm-out (armpits 22 mm apart), at most 1.9 mm on the
/// other bodies. The tab stood out 9.2 mm on arm-out.
const UNDERARM_EXCESS_MM: f64 = 4.0;

/// The most a torso layer within [`UNDERARM_DEPTH_MM`] below the mannequin's own armpits
/// reaches further from the plane than the body's torso reaches from its centre line at the
/// same depth below either of the body's armpits (mm), and that layer's height. Between two
/// armpits at different heights the body's sections hold one side's underarm only: averaged
/// into both sides, it stood out under the arm plates as a flat tab (6 mm on `dressform
/// demo`'s re-posed customer, whose armpits are 14.5 mm apart).
fn underarm_excess(scan: &SegmentedBody, m: &Mannequin) -> (f64, f64) {
    let (lm, armpit) = (&m.landmarks, m.own_landmarks().left_armpit);
    let under: Vec<&Layer> =
        m.torso.iter().filter(|l| l.z < armpit && l.z >= armpit - UNDERARM_DEPTH_MM).collect();
    let depth_below = |l: &Layer| [lm.left_armpit, lm.right_armpit].map(|a| a - (armpit - l.z));
    let heights: Vec<f64> = under.iter().flat_map(|l| depth_below(l)).collect();
    let reach = |c: &Option<Contour>, side: f64| {
        let c = c.as_ref().expect("a torso section below an armpit");
        c.points.iter().map(|p| side * (p.x - lm.centre_x)).fold(f64::NEG_INFINITY, f64::max)
    };
    let half = |l: &Layer| l.points.iter().map(|p| (p.x - m.axis).abs()).fold(0.0, f64::max);
    under
        .iter()
        .zip(scan.torso_sections(&heights).chunks_exact(2))
        .map(|(l, s)| (half(l) - reach(&s[0], 1.0).max(reach(&s[1], -1.0)), l.z))
        .fold((f64::NEG_INFINITY, f64::NAN), |best, e| if e.0 > best.0 { e } else { best })
}

fn report(case: &Case, out: &Symmetrized) -> Report {
    let m = &out.mannequin;
    let lm = &m.landmarks;
    let heights: Vec<f64> = m.torso.iter().map(|l| l.z).collect();
    let scan = SegmentedBody::with_regions(&case.scan.body, &out.regions);
    let input = scan.torso_sections(&heights);
    let ours = dressform::shape::measure::central_loops(&m.mesh, m.axis, &heights);
    // Below the shoulder cap every layer keeps its section's girth; within it the mesh's
    // rings are bent over the shoulders, and its horizontal sections are reported.
    let shoulders = lm.left_armhole.shoulder_point.z.min(lm.right_armhole.shoulder_point.z);
    let (mut torso_girth_change, mut cap_girth_change, mut recorded_girth_error) =
        (0.0_f64, 0.0_f64, 0.0_f64);
    for ((layer, a), b) in m.torso.iter().zip(&input).zip(&ours) {
        let (Some(a), Some(b)) = (a, b) else { panic!("{}: no loop at {}", case.name, layer.z) };
        let change = (a.tape_girth() - b.tape_girth()).abs();
        if layer.z < m.shoulder_cap_from {
            torso_girth_change = torso_girth_change.max(change);
            recorded_girth_error =
                recorded_girth_error.max((layer.tape_girth - b.tape_girth()).abs());
        } else {
            cap_girth_change = cap_girth_change.max(change);
        }
    }
    let above: Vec<f64> =
        (0..).map(|k| shoulders + SLICE_STEP_MM * k as f64).take_while(|&z| z < lm.neck).collect();
    let largest_jump = |loops: &[Option<dressform::body::slice::Contour>]| {
        let w: Vec<f64> = loops
            .iter()
            .flatten()
            .map(|c| 2.0 * c.points.iter().map(|p| (p.x - m.axis).abs()).fold(0.0, f64::max))
            .collect();
        w.windows(2).map(|p| (p[1] - p[0]).abs()).fold(0.0, f64::max)
    };
    let shoulder_jump = (
        largest_jump(&scan.torso_sections(&above)),
        width_jump(&m.mesh, shoulders, f64::INFINITY).0,
    );
    let band = (lm.crotch, lm.crotch + CROTCH_BAND_MM);
    // The input's torso and legs: its arms hang beside the hips in this band.
    let (input_body, mut body) = (&case.scan.body, case.scan.body.clone());
    let armpit_x = [lm.left_armhole, lm.right_armhole]
        .iter()
        .map(|a| (a.armpit.x - lm.centre_x).abs())
        .fold(0.0, f64::max);
    body.retain_triangles(|t| {
        input_body.corners(t).iter().all(|p| (p.x - lm.centre_x).abs() <= ARMS_BEYOND * armpit_x)
    });
    let leg_heights: Vec<f64> = m.left_leg.iter().map(|l| l.z).collect();
    let input_leg = |region| {
        let sections = scan.sections_of(region, &leg_heights);
        let centres: Vec<(f64, f64)> = leg_heights
            .iter()
            .zip(&sections)
            .map(|(&z, c)| (z, c.as_ref().expect("a leg section").bbox_centre().x))
            .collect();
        abduction_deg(&centres)
    };
    let mannequin_leg: Vec<(f64, f64)> = m.left_leg.iter().map(|l| (l.z, l.centre[0])).collect();
    let mannequin_lean: Vec<(f64, f64)> = m.left_leg.iter().map(|l| (l.z, l.centre[1])).collect();
    let leg_gap = m
        .left_leg
        .iter()
        .map(|l| 2.0 * l.points.iter().map(|p| p.x - m.axis).fold(f64::INFINITY, f64::min))
        .fold(f64::INFINITY, f64::min);
    Report {
        name: case.name.clone(),
        width_jump: width_jump(&m.mesh, f64::NEG_INFINITY, shoulders),
        underarm_excess: underarm_excess(&scan, m),
        self_intersections: self_intersecting_pairs(&m.mesh).len(),
        crotch_ledge: near_horizontal_area(&m.mesh, band.0, band.1, HORIZONTAL_TILT_DEG),
        body_crotch_ledge: near_horizontal_area(&body, band.0, band.1, HORIZONTAL_TILT_DEG).0,
        crotch_change: crotch_on_plane(&m.mesh, m.axis) - lm.crotch,
        seam_crease: crotch_creases(&m.mesh, m.axis, lm.crotch),
        join_line: join_line(&m.mesh, m.axis, lm.crotch),
        thigh_crease: thigh_creases(&m.mesh, m.axis, lm.crotch),
        join_ticks: join_ticks(&m.mesh, m.axis, lm.crotch),
        mirror_gap: largest_mirror_gap(&m.mesh, m.axis),
        torso_girth_change,
        cap_girth_change,
        bent_below_shoulders: shoulders - m.shoulder_cap_from,
        shoulder_jump,
        recorded_girth_error,
        leg_deg: [
            input_leg(Region::LeftLeg),
            -input_leg(Region::RightLeg),
            abduction_deg(&mannequin_leg),
        ],
        leg_flexion_deg: flexion_deg(&mannequin_lean),
        legs: m.options.legs,
        leg_gap,
        shoulder_line: case.acromions.map(|a| shoulder_line_gap(case, out, a)),
        rim: {
            let plate = m.own_landmarks().left_armhole;
            plate_rim(&m.mesh, plate.armpit, plate.normal)
        },
    }
}

/// Where the shoulder line starts beside the neck: this far outside the neck's top layer (mm).
const BESIDE_NECK_MM: f64 = 10.0;
/// Where it ends: this far inside the acromion or the armhole (mm), where the arm plate begins.
const INSIDE_ACROMION_MM: f64 = 5.0;

/// The largest height difference (mm) between the front silhouettes' shoulder lines of the
/// mannequin and of the body (the mean of its left side and its mirrored right side), from
/// beside the neck to the armhole, below the neck.
fn shoulder_line_gap(case: &Case, out: &Symmetrized, acromions: [DVec3; 2]) -> f64 {
    let m = &out.mannequin;
    let neck = m.torso.last().expect("torso layers");
    let neck_half = neck.points.iter().map(|p| (p.x - m.axis).abs()).fold(0.0, f64::max);
    // The line ends at the acromion or, where the armhole's shoulder point is found inside it,
    // at the mannequin's armhole.
    let lm = &m.landmarks;
    let armhole = [lm.left_armhole, lm.right_armhole]
        .iter()
        .map(|a| 0.5 * (a.shoulder_point.x - m.axis).abs())
        .sum::<f64>();
    let reach = (0.5 * (acromions[0].x - acromions[1].x)).min(armhole) - INSIDE_ACROMION_MM;
    let offsets: Vec<f64> =
        (0..).map(|k| neck_half + BESIDE_NECK_MM + k as f64).take_while(|&u| u <= reach).collect();
    let at = |mesh: &Mesh, sign: f64| {
        let xs: Vec<f64> = offsets.iter().map(|u| m.axis + sign * u).collect();
        silhouette_top(mesh, &xs, neck.z)
    };
    let (left, right, ours) =
        (at(&case.scan.body, 1.0), at(&case.scan.body, -1.0), at(&m.mesh, 1.0));
    assert!(!offsets.is_empty(), "{}: no shoulder between the neck and the acromion", case.name);
    (0..offsets.len())
        .map(|k| {
            let body = 0.5 * (left[k].expect("body") + right[k].expect("body"));
            (ours[k].expect("mannequin") - body).abs()
        })
        .fold(0.0, f64::max)
}

/// How far out from the torso's centre line the hanging arms are, in armpit half-widths.
const ARMS_BEYOND: f64 = 1.5;

/// A leg's abduction from its section centres (height, x): the angle from vertical of the
/// least-squares line x(z), positive with the foot outward to +X.
fn abduction_deg(centres: &[(f64, f64)]) -> f64 {
    lean_deg(centres)
}

/// A leg's lean forward from its section centres (height, y): the angle from vertical of the
/// least-squares line y(z), positive with the foot forward (to -Y, the way the subject faces).
fn flexion_deg(centres: &[(f64, f64)]) -> f64 {
    -lean_deg(centres)
}

/// The angle from vertical of the least-squares line c(z) through `centres` (height, c),
/// positive where c grows downward.
fn lean_deg(centres: &[(f64, f64)]) -> f64 {
    let n = centres.len() as f64;
    let (mz, mx) = centres.iter().fold((0.0, 0.0), |(a, b), &(z, x)| (a + z / n, b + x / n));
    let (szz, szx) = centres
        .iter()
        .fold((0.0, 0.0), |(a, b), &(z, x)| (a + (z - mz) * (z - mz), b + (z - mz) * (x - mx)));
    (-szx / szz).atan().to_degrees()
}

fn look(case: &Case, out: &Symmetrized) {
    let Some(dir) = std::env::var_os("DRESSFORM_LOOK") else { return };
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).unwrap();
    for (what, mesh) in [("input", &case.scan.body), ("mannequin", &out.mannequin.mesh)] {
        std::fs::write(dir.join(format!("{}-{what}.obj", case.name)), Format::Obj.encode(mesh))
            .unwrap();
    }
}

/// Builds every case's mannequin with `options`, prints the table and checks every row.
fn check_all(cases: Vec<Case>, options: &MannequinOptions) {
    check_reports(
        cases
            .par_iter()
            .map(|case| {
                let out = symmetrize(&case.scan, options, |_| {})
                    .unwrap_or_else(|e| panic!("{}: {e}", case.name));
                look(case, &out);
                report(case, &out)
            })
            .collect(),
    );
}

/// Prints the table of `reports` and checks every row.
fn check_reports(reports: Vec<Report>) {
    eprintln!(
        "{:<12} {:>15} {:>15} {:>9} {:>22} {:>7} {:>11} {:>9} {:>11} {:>6} {:>7} {:>7} {:>15} {:>13} {:>23} {:>7} {:>8} {:>14}",
        "mannequin",
        "width jump (z)",
        "underarm (z)",
        "crossing",
        "ledge mm2: max/all/body",
        "crotch",
        "seam/around",
        "join/rings",
        "thigh/below",
        "ticks",
        "mirror",
        "girth",
        "bent/cap girth",
        "jump body/us",
        "legs deg: L/R/out/fwd",
        "leg gap",
        "line",
        "rim deg/n/flat"
    );
    for r in &reports {
        eprintln!(
            "{:<12} {:>6.1} ({:>6.0}) {:>6.1} ({:>6.0}) {:>9} {:>6.1} {:>7.0} {:>7.0} {:>+7.2} {:>5.1}/{:>5.1} {:>4.1}/{:>4.1} {:>5.1}/{:>5.1} {:>6.1} {:>7.3} {:>7.3} {:>7.1}/{:>7.1} {:>6.1}/{:>6.1} {:>5.1} {:>5.1} {:>5.1} {:>5.2} {:>7.1} {:>8} {:>14}",
            r.name,
            r.width_jump.0,
            r.width_jump.1,
            r.underarm_excess.0,
            r.underarm_excess.1,
            r.self_intersections,
            r.crotch_ledge.1,
            r.crotch_ledge.0,
            r.body_crotch_ledge,
            r.crotch_change,
            r.seam_crease.0,
            r.seam_crease.1,
            r.join_line.0,
            r.join_line.1,
            r.thigh_crease.0,
            r.thigh_crease.1,
            r.join_ticks,
            r.mirror_gap,
            r.torso_girth_change,
            r.bent_below_shoulders,
            r.cap_girth_change,
            r.shoulder_jump.0,
            r.shoulder_jump.1,
            r.leg_deg[0],
            r.leg_deg[1],
            r.leg_deg[2],
            r.leg_flexion_deg,
            r.leg_gap,
            r.shoulder_line.map_or("-".into(), |g| format!("{g:.1}")),
            r.rim.map_or("-".into(), |r| format!(
                "{:.0}/{}/{:.1}",
                r.turning_deg, r.vertices, r.flat_bottom_mm
            ))
        );
    }
    for r in &reports {
        let name = &r.name;
        assert_eq!(r.self_intersections, 0, "{name}: self-intersecting triangle pairs");
        assert!(r.width_jump.0 <= WIDTH_JUMP_MM, "{name}: width jump {:?}", r.width_jump);
        assert!(
            r.underarm_excess.0 <= UNDERARM_EXCESS_MM,
            "{name}: a tab under the arm plates: {:?}",
            r.underarm_excess
        );
        // Over the whole height, the shoulders too: the mannequin's shoulder top is never
        // flatter than a dress form's, even where the body's is (MakeHuman's, 126 mm).
        assert!(
            r.shoulder_jump.1 <= WIDTH_JUMP_MM,
            "{name}: the width jumps above the shoulder points: {:?} (body, mannequin)",
            r.shoulder_jump
        );
        if let Some(gap) = r.shoulder_line {
            assert!(gap <= SHOULDER_LINE_MM, "{name}: shoulder line {gap:.1} mm from the body's");
        }
        assert!(r.crotch_ledge.1 <= LEDGE_FACE_MM2, "{name}: a ledge at the crotch: {r:?}");
        assert!(
            r.crotch_ledge.0 <= r.body_crotch_ledge + LEDGE_FACE_MM2,
            "{name}: flatter at the crotch than the body: {r:?}"
        );
        assert!(r.seam_crease.0 <= SEAM_CREASE_DEG, "{name}: the crotch join creases: {r:?}");
        assert!(
            r.join_line.0 <= r.join_line.1 + JOIN_LINE_DEG,
            "{name}: a line along the crotch join: {:?}",
            r.join_line
        );
        assert!(
            r.thigh_crease.0 <= r.thigh_crease.1 + THIGH_CREASE_DEG,
            "{name}: a line across the thighs below the crotch: {:?}",
            r.thigh_crease
        );
        assert!(
            r.join_ticks <= JOIN_TICKS_DEG,
            "{name}: a line of creases along the legs' top ring: {:.1} deg",
            r.join_ticks
        );
        assert!(r.crotch_change.abs() <= 2.0, "{name}: crotch height {:+.2} mm", r.crotch_change);
        assert!(
            r.mirror_gap < 0.1,
            "{name}: a vertex {:.3} mm from its mirror partner",
            r.mirror_gap
        );
        assert!(r.torso_girth_change < 0.1, "{name}: a torso layer's girth changed: {r:?}");
        assert!(r.bent_below_shoulders <= 0.0, "{name}: rings bent below the shoulders: {r:?}");
        let rim = r.rim.unwrap_or_else(|| panic!("{name}: no flat arm plate"));
        let (turning, flat) = (rim.turning_deg, rim.flat_bottom_mm);
        assert!(turning <= RIM_TURNING_DEG, "{name}: the arm plate's rim turns {turning:.0} deg");
        assert!(flat <= RIM_FLAT_BOTTOM_MM, "{name}: the arm plate's rim is flat for {flat:.1} mm");
        assert!(r.recorded_girth_error < 0.1, "{name}: a layer misreports its girth: {r:?}");
        assert!(r.leg_gap >= 0.0, "{name}: the legs run into each other: {:.1} mm", r.leg_gap);
        match r.legs {
            // Parallel and vertical.
            LegStance::Straight => assert!(
                r.leg_deg[2].abs() <= STRAIGHT_LEG_DEG
                    && r.leg_flexion_deg.abs() <= STRAIGHT_LEG_DEG,
                "{name}: the legs lean {:.2} deg out and {:.2} forward",
                r.leg_deg[2],
                r.leg_flexion_deg
            ),
            // The mean of the left leg's direction and the right leg's mirrored.
            LegStance::AsScanned => {
                let stance = 0.5 * (r.leg_deg[0] + r.leg_deg[1]);
                let off = (r.leg_deg[2] - stance).abs();
                assert!(off < LEG_STANCE_DEG, "{name}: legs {:?}", r.leg_deg);
            }
        }
    }
}

#[test]
fn the_demo_customer_the_asymmetric_example_and_the_makehuman_body() {
    let mut cases = vec![demo_customer(), asymmetric(), arm_out()];
    cases.extend(makehuman_base());
    check_all(cases, &MannequinOptions::default());
}

/// Legs standing as the customer stood: the demo's customer (legs 6 degrees out) and the
/// asymmetric example (the left leg 15 degrees out, the right 6) and the MakeHuman body (whose
/// thighs nearly touch).
#[test]
fn legs_as_scanned() {
    let options = MannequinOptions { legs: LegStance::AsScanned, ..Default::default() };
    let mut cases = vec![arm_out(), asymmetric()];
    cases.extend(makehuman_base());
    check_all(cases, &options);
}

#[test]
fn twenty_random_customers() {
    let cases: Vec<Case> = (0..20)
        .into_par_iter()
        .map(|s| generated(format!("random-{s}"), &BodyParams::random(s)))
        .collect();
    check_all(cases, &MannequinOptions::default());
}

/// A body through `reconstruct` (pose symmetry, then the mannequin): the pose-symmetric scan
/// is the mannequin's input.
fn reconstructed(name: &str, scan: &Scan) -> Report {
    let rec = reconstruct(scan, &BodyModel::builtin(), &ReconstructOptions::default(), |_| {})
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let case = Case { name: name.into(), scan: rec.reposed.posed, acromions: None };
    look(&case, &rec.result);
    report(&case, &rec.result)
}

/// The MakeHuman body with a full hourglass shape, its left arm 15 degrees further out and its
/// right leg 6 degrees out, scanned as its skin (canonical frame, floor and units detected).
fn posed_makehuman() -> Option<Scan> {
    let dir = makehuman()?;
    let mh = MakeHuman::load(&dir).expect("the MakeHuman assets load");
    let body = mh.shaped(&[("bodyshapes/bodyshapes-elvs-fem-full-hourglass", 0.6)]).unwrap();
    let pose = MhPose::rest()
        .rotate("upperarm01.L", DVec3::Y * (-15.0_f64).to_radians())
        .rotate("upperleg01.R", DVec3::Y * 6.0_f64.to_radians());
    let skin = mh.base.skin(&mh.pose(&body, &pose).unwrap());
    Some(scan::from_mesh(skin, Path::new("posed-makehuman"), &FrameOptions::default()).unwrap())
}

/// The bodies `dressform demo` and `reconstruct` make mannequins of: the demo customer's scan
/// and a posed MakeHuman body, each through pose symmetry.
#[test]
fn reconstructed_bodies() {
    let mut scans = vec![("demo-rec", demo_customer().scan)];
    scans.extend(posed_makehuman().map(|s| ("mh-posed-rec", s)));
    check_reports(scans.par_iter().map(|(name, scan)| reconstructed(name, scan)).collect());
}
