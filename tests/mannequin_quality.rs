//! A mannequin a tailor would accept, on every kind of body we have: the demo customer (scanned
//! with a scanner's artifacts), 20 random customers of the sim generator, its asymmetric
//! example and the MakeHuman base body. Each test prints its numbers.
//!
//! Set `DRESSFORM_LOOK=<dir>` to also write every body's input and mannequin there as OBJ, to
//! render them (`python3 ../shared/tools/look.py out.png <dir>/<name>-mannequin.obj`).

use crate::common;

use common::quality::{
    creases, largest_crease, near_horizontal_area, plate_rim_turning, self_intersecting_pairs,
    silhouette_top, width_jump,
};
use common::{largest_mirror_gap, makehuman, surface_mesh as mesh_of};
use dressform::mannequin::MannequinOptions;
use dressform::mesh::{Mesh, smooth::DEFAULT_PASSES};
use dressform::pipeline::{Symmetrized, symmetrize};
use dressform::regions::Region;
use dressform::scan::{self, Scan, format::Format, frame::FrameOptions};
use dressform::segmented_body::SegmentedBody;
use glam::DVec3;
use rayon::prelude::*;
use sim::capture::{Artifacts, BodyParams, Pose, SyntheticBody, capture, generate};
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
    let body = generate(&BodyParams::default()).unwrap();
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
    /// The largest height difference between the mannequin's shoulder line and the body's
    /// (mm), where the shoulders are known.
    shoulder_line: Option<f64>,
    /// The left arm plate's rim: its total turning (degrees) and its vertex count.
    rim: Option<(f64, usize)>,
}

/// How far above the crotch the ledge check looks (mm), from the issue.
const CROTCH_BAND_MM: f64 = 50.0;
/// "Near-horizontal": a face normal within this angle of vertical (degrees), from the issue.
const HORIZONTAL_TILT_DEG: f64 = 10.0;
/// The spacing of the slices the width jump compares (mm), from the definition.
const SLICE_STEP_MM: f64 = 2.0;
/// The largest width jump allowed (mm), from the issue: a smooth body stays under it.
const WIDTH_JUMP_MM: f64 = 15.0;
/// How much more the mannequin's width may jump above the shoulder points than the body's own
/// torso (or [`WIDTH_JUMP_MM`], where that is more) does (mm). Above the shoulder points the
/// mannequin follows the body's shoulder top, slope and girths kept, so where the top is
/// nearly level its width jumps as the body's does (MakeHuman's 126 mm, the asymmetric
/// example's 119); the rings (6.6 mm of height apart) may put a level top's change into one
/// pair of slices where the body spreads it over two: 11 mm more on MakeHuman, 6 on the
/// generator's bodies.
const SHOULDER_JUMP_MARGIN_MM: f64 = 15.0;
/// How far the mannequin's shoulder line may be from the body's (mm), from the issue.
const SHOULDER_LINE_MM: f64 = 5.0;
/// How close the mannequin's leg direction is to the mean of the input's (degrees).
const LEG_STANCE_DEG: f64 = 0.5;
/// The most the left arm plate's rim may turn in all (degrees): a convex curve turns 360, and
/// each step of a staircase (one per layer, 15-20 layers up each side) adds about 180; the
/// rims, one curve, turn 360-422 degrees on the generator's bodies and 534 on the demo's
/// noisy scan.
const RIM_TURNING_DEG: f64 = 560.0;
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

fn report(case: &Case, out: &Symmetrized) -> Report {
    let m = &out.mannequin;
    let lm = &m.landmarks;
    let heights: Vec<f64> = m.torso.iter().map(|l| l.z).collect();
    let scan = SegmentedBody::with_regions(&case.scan.body, &out.regions);
    let input = scan.torso_sections(&heights);
    let ours = dressform::measure::central_loops(&m.mesh, m.axis, &heights);
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
    let largest_jump = |loops: &[Option<dressform::slice::Contour>]| {
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
    Report {
        name: case.name.clone(),
        width_jump: width_jump(&m.mesh, f64::NEG_INFINITY, shoulders),
        self_intersections: self_intersecting_pairs(&m.mesh).len(),
        crotch_ledge: near_horizontal_area(&m.mesh, band.0, band.1, HORIZONTAL_TILT_DEG),
        body_crotch_ledge: near_horizontal_area(&body, band.0, band.1, HORIZONTAL_TILT_DEG).0,
        crotch_change: crotch_on_plane(&m.mesh, m.axis) - lm.crotch,
        seam_crease: crotch_creases(&m.mesh, m.axis, lm.crotch),
        join_line: join_line(&m.mesh, m.axis, lm.crotch),
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
        shoulder_line: case.acromions.map(|a| shoulder_line_gap(case, out, a)),
        rim: {
            let plate = m.own_landmarks().left_armhole;
            plate_rim_turning(&m.mesh, plate.armpit, plate.normal)
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

/// Builds every case's mannequin, prints the table and checks every row.
fn check_all(cases: Vec<Case>) {
    let reports: Vec<Report> = cases
        .par_iter()
        .map(|case| {
            let out = symmetrize(&case.scan, &MannequinOptions::default(), |_| {})
                .unwrap_or_else(|e| panic!("{}: {e}", case.name));
            look(case, &out);
            report(case, &out)
        })
        .collect();
    eprintln!(
        "{:<12} {:>15} {:>9} {:>22} {:>7} {:>11} {:>9} {:>7} {:>7} {:>15} {:>13} {:>17} {:>8} {:>10}",
        "mannequin",
        "width jump (z)",
        "crossing",
        "ledge mm2: max/all/body",
        "crotch",
        "seam/around",
        "join/rings",
        "mirror",
        "girth",
        "bent/cap girth",
        "jump body/us",
        "legs deg: L/R/out",
        "line",
        "rim deg/n"
    );
    for r in &reports {
        eprintln!(
            "{:<12} {:>6.1} ({:>6.0}) {:>9} {:>6.1} {:>7.0} {:>7.0} {:>+7.2} {:>5.1}/{:>5.1} {:>4.1}/{:>4.1} {:>7.3} {:>7.3} {:>7.1}/{:>7.1} {:>6.1}/{:>6.1} {:>5.1} {:>5.1} {:>5.1} {:>8} {:>10}",
            r.name,
            r.width_jump.0,
            r.width_jump.1,
            r.self_intersections,
            r.crotch_ledge.1,
            r.crotch_ledge.0,
            r.body_crotch_ledge,
            r.crotch_change,
            r.seam_crease.0,
            r.seam_crease.1,
            r.join_line.0,
            r.join_line.1,
            r.mirror_gap,
            r.torso_girth_change,
            r.bent_below_shoulders,
            r.cap_girth_change,
            r.shoulder_jump.0,
            r.shoulder_jump.1,
            r.leg_deg[0],
            r.leg_deg[1],
            r.leg_deg[2],
            r.shoulder_line.map_or("-".into(), |g| format!("{g:.1}")),
            r.rim.map_or("-".into(), |(t, n)| format!("{t:.0}/{n}"))
        );
    }
    for r in &reports {
        let name = &r.name;
        assert_eq!(r.self_intersections, 0, "{name}: self-intersecting triangle pairs");
        assert!(r.width_jump.0 <= WIDTH_JUMP_MM, "{name}: width jump {:?}", r.width_jump);
        assert!(
            r.shoulder_jump.1 <= r.shoulder_jump.0.max(WIDTH_JUMP_MM) + SHOULDER_JUMP_MARGIN_MM,
            "{name}: the width jumps above the shoulder points more than the body's: {:?}",
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
        assert!(r.crotch_change.abs() <= 2.0, "{name}: crotch height {:+.2} mm", r.crotch_change);
        assert!(
            r.mirror_gap < 0.1,
            "{name}: a vertex {:.3} mm from its mirror partner",
            r.mirror_gap
        );
        assert!(r.torso_girth_change < 0.1, "{name}: a torso layer's girth changed: {r:?}");
        assert!(r.bent_below_shoulders <= 0.0, "{name}: rings bent below the shoulders: {r:?}");
        let (turning, _) = r.rim.unwrap_or_else(|| panic!("{name}: no flat arm plate"));
        assert!(turning <= RIM_TURNING_DEG, "{name}: the arm plate's rim turns {turning:.0} deg");
        assert!(r.recorded_girth_error < 0.1, "{name}: a layer misreports its girth: {r:?}");
        // The stance: the mean of the left leg's direction and the right leg's mirrored.
        let stance = 0.5 * (r.leg_deg[0] + r.leg_deg[1]);
        assert!((r.leg_deg[2] - stance).abs() < LEG_STANCE_DEG, "{name}: legs {:?}", r.leg_deg);
    }
}

#[test]
fn the_demo_customer_the_asymmetric_example_and_the_makehuman_body() {
    let mut cases = vec![demo_customer(), asymmetric()];
    cases.extend(makehuman_base());
    check_all(cases);
}

#[test]
fn twenty_random_customers() {
    let cases: Vec<Case> = (0..20)
        .into_par_iter()
        .map(|s| generated(format!("random-{s}"), &BodyParams::random(s)))
        .collect();
    check_all(cases);
}
