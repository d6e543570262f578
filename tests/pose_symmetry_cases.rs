//! Issue 15's acceptance table: MakeHuman bodies (shapes including targets the model was not
//! built from) posed with MakeHuman's own 163-bone rig, re-meshed by marching cubes
//! (`tests/scripts/remesh.py`: no vertex of the template survives), with noise, holes at the
//! armpits and the crotch, the crown and the soles cut, some turned by +-20 degrees and written
//! in other units and up axes; in the slightly asymmetric range, with the spine bent sideways,
//! with the head turned, and in the non-standard range. One reconstruction per case; each
//! prints a row with the true and recovered angles and girths, and every miss is collected.
//! Then the same for a different deformer: the sim generator's capsule-limbed bodies.

use crate::common;
use common::Cuts;
use common::frontal::{abduction, elevation};
use common::makehuman_scan::{
    girths, hole_sites, load, pose_of, posed, remesh, remesher, scanned, write_obj,
};
use dressform::body::mesh::Mesh;
use dressform::body::segmented_body::SegmentedBody;
use dressform::pose::body_model::BodyModel;
use dressform::pose::makehuman::MakeHuman;
use dressform::run::reconstruct::{ReconstructOptions, reconstruct};
use dressform::shape::measure::levels;
use glam::{DQuat, DVec3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

/// The scanner's noise (mm), within issue 15's 0.5-1 mm.
const NOISE_MM: f64 = 0.7;
/// The marching-cubes grid's pitch (mm): a body scanner's mesh resolution.
const PITCH_MM: f64 = 5.0;
/// How far in the soles and the crown are cut (mm; a scanner sees neither).
const CUT_MM: f64 = 15.0;
/// How far the pose-symmetric scan's stature may lie outside the truth's (mm): ISO 20685-1's
/// tolerance for stature from a scan.
const STATURE_TOLERANCE_MM: f64 = 4.0;
/// Where the scanner cuts every scan of this table.
const SCANNER: Cuts = Cuts { soles_mm: CUT_MM, crown_mm: CUT_MM };
/// Issue 15's tolerances: limb abduction and clavicle elevation, the spine's summed sideways
/// bend, the head's turn (degrees); chest, waist and hip (mm, each and their mean).
const LIMB_TOLERANCE_DEG: f64 = 3.0;
const SPINE_TOLERANCE_DEG: f64 = 2.0;
const HEAD_TOLERANCE_DEG: f64 = 5.0;
const GIRTH_TOLERANCE_MM: f64 = 5.0;
const GIRTH_MEAN_TOLERANCE_MM: f64 = 3.0;

/// Body shapes, including targets the model was not built from (`bodyshapes/`, `asym/`).
const SHAPES: [&str; 5] = [
    "bodyshapes/bodyshapes-elvs-fem-apple",
    "bodyshapes/bodyshapes-elvs-man-trapezoid",
    "bodyshapes/bodyshapes-elvs-fem-full-hourglass",
    "asym/asymm-trunk-1-l",
    "measure/measure-waist-circ-incr",
];

/// The families of poses in the table.
#[derive(Debug, Clone, Copy)]
enum Family {
    /// Issue 10's range: an arm 10-20 degrees further out with its shoulder 3-8 up, the other
    /// side's leg 3-8 out.
    Slight,
    /// The spine bent 4-8 degrees sideways (over two bones).
    SpineBend,
    /// The head turned 10-25 degrees.
    HeadTurn,
    /// One arm 35-60 out, the trunk bent 6-10 and twisted 6-12, a leg 8-14 out.
    NonStandard,
}

/// How a case's scan file is written: units (mm per unit) and whether Y is up.
const FRAMES: [(&str, f64, bool); 3] =
    [("mm Z-up", 1.0, false), ("m Y-up", 1000.0, true), ("cm Z-up", 10.0, false)];

/// One case: the pose applied (MakeHuman bone, rotation vector) and what it should give back.
struct Case {
    family: Family,
    shape: (&'static str, f64),
    pose: Vec<(String, DVec3)>,
    /// The same body with its arms and legs at the model's rest and the spine and head
    /// straight (none of the cases bends forward): what the pose-symmetric scan should be.
    symmetric: Vec<(String, DVec3)>,
    /// The spine's summed sideways bend and twist, the head's turn (degrees).
    spine_bend: f64,
    spine_twist: f64,
    head_turn: f64,
    yaw_deg: f64,
    frame: usize,
}

/// The turn about `axis` by `deg` degrees as a rotation vector.
fn turn(axis: DVec3, deg: f64) -> DVec3 {
    axis * deg.to_radians()
}

fn case(index: u64, family: Family) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(1500 + index);
    let shape = (SHAPES[index as usize % SHAPES.len()], rng.random_range(0.3..1.0));
    // The left side turns outwards about -Y, the right about +Y.
    let (arm, leg, out) =
        if index.is_multiple_of(2) { (".L", ".R", -1.0) } else { (".R", ".L", 1.0) };
    let (arm_deg, shoulder_deg, leg_deg, bend, twist, head) = match family {
        Family::Slight => (
            rng.random_range(10.0..20.0),
            rng.random_range(3.0..8.0),
            rng.random_range(3.0..8.0),
            0.0,
            0.0,
            0.0,
        ),
        Family::SpineBend => (0.0, 0.0, 0.0, rng.random_range(4.0..8.0), 0.0, 0.0),
        Family::HeadTurn => (0.0, 0.0, 0.0, 0.0, 0.0, rng.random_range(10.0..25.0)),
        Family::NonStandard => (
            rng.random_range(35.0..60.0),
            0.0,
            rng.random_range(8.0..14.0),
            rng.random_range(6.0..10.0),
            rng.random_range(6.0..12.0),
            0.0,
        ),
    };
    let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let (bend, twist, head) = (bend * side, twist * side, head * side);
    // One side out by the case's angles, the other at rest.
    let mut pose = vec![
        (format!("upperarm01{arm}"), turn(DVec3::Y, out * arm_deg)),
        (format!("clavicle{arm}"), turn(DVec3::Y, out * shoulder_deg)),
        (format!("upperleg01{leg}"), turn(DVec3::Y, -out * leg_deg)),
    ];
    for bone in ["spine03", "spine02"] {
        pose.push((bone.into(), turn(DVec3::Y, bend / 2.0) + turn(DVec3::Z, twist / 2.0)));
    }
    pose.push(("head".into(), turn(DVec3::Z, head)));
    let yaw_deg = if index % 4 == 3 { 20.0 * side } else { 0.0 };
    Case {
        family,
        shape,
        pose,
        symmetric: Vec::new(),
        spine_bend: bend,
        spine_twist: twist,
        head_turn: head,
        yaw_deg,
        frame: index as usize % FRAMES.len(),
    }
}

/// The table: at least 20 cases over the four families.
fn cases() -> Vec<Case> {
    let families = [
        (Family::Slight, 7),
        (Family::SpineBend, 3),
        (Family::HeadTurn, 3),
        (Family::NonStandard, 7),
    ];
    let mut all = Vec::new();
    for (family, count) in families {
        for _ in 0..count {
            all.push(case(all.len() as u64, family));
        }
    }
    all
}

/// Arm, clavicle and leg angles per side (L then R) of joints `at(name)` seen in `frame`.
fn limb_angles(at: impl Fn(&str) -> DVec3, frame: DQuat) -> Vec<f64> {
    let mut angles = Vec::new();
    for side in [".L", ".R"] {
        let j = |bone: &str| frame.inverse() * at(&format!("{bone}{side}"));
        angles.push(abduction(j("upperarm01"), j("lowerarm01")));
        angles.push(elevation(j("clavicle"), j("upperarm01")));
        angles.push(abduction(j("upperleg01"), j("lowerleg01")));
    }
    angles
}

const LIMB_NAMES: [&str; 6] = ["arm.L", "clav.L", "leg.L", "arm.R", "clav.R", "leg.R"];

/// Whether an error is over its limit, or not a number (a section that was not found).
fn exceeds(error: f64, limit: f64) -> bool {
    error.is_nan() || error > limit
}

#[test]
fn reconstruct_recovers_poses_and_girths_over_the_acceptance_table() {
    let Some(dir) = common::makehuman() else { return };
    let Some(python) = remesher() else { return };
    let mh = MakeHuman::load(&dir).expect("the MakeHuman assets load");
    let model = BodyModel::builtin();
    let tmp = tempfile::tempdir().unwrap();
    let cases = cases();
    // All the re-meshing in one Python run: each case's scan, and its truth (the same body in
    // the symmetric pose) scanned alike.
    let mut pairs = Vec::new();
    let mut truths = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let body = mh.shaped(&[case.shape]).unwrap();
        let mut heads_and_floors = Vec::new();
        for (name, bones) in [("scan", &case.pose), ("truth", &case.symmetric)] {
            let (source, target) = (
                tmp.path().join(format!("{name}{i}.obj")),
                tmp.path().join(format!("{name}{i}.ply")),
            );
            let skin = posed(&mh, &body, bones);
            write_obj(&skin, &source);
            pairs.push((source, target));
            let heads = mh.rig.bone_heads(&mh.pose(&body, &pose_of(bones)).unwrap());
            heads_and_floors.push((heads, skin.bounds().unwrap().min.z));
        }
        truths.push(heads_and_floors);
    }
    remesh(&python, PITCH_MM, &pairs);

    let mut misses = Vec::new();
    let mut worst = [0.0f64; 5];
    for (i, (case, bodies)) in cases.iter().zip(&truths).enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(2500 + i as u64);
        let remeshed = |name: &str| {
            let path = tmp.path().join(format!("{name}{i}.ply"));
            dressform::body::scan::read_mesh(&path).unwrap().0
        };
        let [(heads, floor), (truth_heads, truth_floor)] = [&bodies[0], &bodies[1]];
        let joint = |name: &str| heads[mh.rig.bone(name).unwrap()];
        let scan = scanned(
            &remeshed("scan"),
            *floor,
            &hole_sites(&mh, heads),
            SCANNER,
            NOISE_MM,
            &mut rng,
        );
        let yaw = DQuat::from_rotation_z(case.yaw_deg.to_radians());
        let (frame_name, unit, y_up) = FRAMES[case.frame];
        let file = scan.map_positions(|p| {
            let q = yaw * p / unit;
            if y_up { DVec3::new(q.x, q.z, -q.y) } else { q }
        });
        let path = tmp.path().join(format!("scan{i}.obj"));
        write_obj(&file, &path);
        let loaded = load(&path);
        let rec = match reconstruct(&loaded, &model, &ReconstructOptions::default(), |_| {}) {
            Ok(rec) => rec,
            Err(e) => {
                misses.push((i, "reconstruct".to_string(), e.to_string()));
                continue;
            }
        };

        // Angles: the truth in the body's own frame, the fit's in its root's (the yaw).
        let names = &model.skeleton.names;
        let bone = |name: &str| names.iter().position(|n| n == name).unwrap();
        let fitted_joints = rec.reposed.fit.joints(&rec.reposed.model);
        let root = DQuat::from_scaled_axis(rec.reposed.fit.theta[0]);
        let want = limb_angles(joint, DQuat::IDENTITY);
        let got = limb_angles(|n| fitted_joints[bone(n)], root);
        let sum = |bones: &[&str], axis: usize| -> f64 {
            bones.iter().map(|b| rec.reposed.fit.theta[bone(b)][axis].to_degrees()).sum()
        };
        let spine = ["spine04", "spine03", "spine02", "spine01"];
        let (bend, twist) = (sum(&spine, 1), sum(&spine, 2));
        let head = sum(&["neck01", "head"], 2);

        // Girths: the truth is the same body in the symmetric pose, scanned alike (re-meshed,
        // noise, holes at the same places on the body, soles and crown cut) and loaded the same
        // way; both cut at its chest, waist and hip levels. (Against the un-holed body the chest
        // at the bust point missed by 6-19 mm on 9 cases: the scan's holes under the arms lie at
        // the bust's height and cut the corners of the tape.)
        let truth_sites = hole_sites(&mh, truth_heads);
        // The same truth with its crown kept (the same noise), for the stature below.
        let (truth, crowned) = {
            let scan = |cuts: Cuts, mut rng: ChaCha8Rng, name: &str| {
                let mesh = scanned(
                    &remeshed("truth"),
                    *truth_floor,
                    &truth_sites,
                    cuts,
                    NOISE_MM,
                    &mut rng,
                );
                let path = tmp.path().join(format!("{name}{i}.obj"));
                write_obj(&mesh, &path);
                load(&path)
            };
            let kept = Cuts { crown_mm: 0.0, ..SCANNER };
            let seed = rng.random::<u64>();
            let rng = || ChaCha8Rng::seed_from_u64(seed);
            (scan(SCANNER, rng(), "truth_scan"), scan(kept, rng(), "crowned_truth"))
        };
        let at = levels(&SegmentedBody::find(&truth.body).unwrap());
        let heights = [at.chest, at.waist, at.hip];
        let girth_want = girths(&truth.body, 0.0, &heights);
        let girth_got = girths(&rec.reposed.posed.body, 0.0, &heights);
        let girth_err: Vec<f64> =
            girth_want.iter().zip(&girth_got).map(|(a, b)| (a - b).abs()).collect();
        let girth_mean = girth_err.iter().sum::<f64>() / 3.0;
        let stature = |body: &Mesh| SegmentedBody::find(body).unwrap().landmarks().height;
        // The scanner cut the crown flat, 15 mm below the top of the head as it stood; the
        // straightening tilts that cut, and its rim's high side then lies above the truth's
        // level cut: up to 6.4 mm on the spine-bend and non-standard cases, growing with the
        // bend (case 13: the rim, radius 49 mm, tilted 8.9 degrees, its highest point 7.4 mm
        // above its centre; the truth's rim level, its highest point 1.6 mm above), and within
        // 1.3 mm of the truth on every case when neither scan loses its crown. So the stature
        // is right when it lies between the truth's with the crown cut and with the crown kept.
        let stature_want = [stature(&truth.body), stature(&crowned.body)];
        let stature_got = stature(&rec.reposed.posed.body);
        let stature_err =
            (stature_want[0] - stature_got).max(stature_got - stature_want[1]).max(0.0);

        let mut row = format!(
            "case {i:2} {:?} {} {:.2} {frame_name} yaw {:+.0}: fit {:.1} s, {} it, rms {:.2}/{:.2} mm |",
            case.family,
            case.shape.0.rsplit('/').next().unwrap(),
            case.shape.1,
            case.yaw_deg,
            rec.reposed.fit_seconds,
            rec.reposed.fit.iterations,
            rec.reposed.fit.residuals.model_to_scan_mm,
            rec.reposed.fit.residuals.scan_to_model_mm,
        );
        for (k, name) in LIMB_NAMES.iter().enumerate() {
            row += &format!(" {name} {:.1}/{:.1}", want[k], got[k]);
            let err = (want[k] - got[k]).abs();
            worst[0] = worst[0].max(err);
            if err > LIMB_TOLERANCE_DEG {
                misses.push((
                    i,
                    name.to_string(),
                    format!("{:.1} recovered as {:.1}", want[k], got[k]),
                ));
            }
        }
        row += &format!(
            " | spine bend {:.1}/{bend:.1} twist {:.1}/{twist:.1} head {:.1}/{head:.1} | chest, waist, hip at {heights:.0?} (result's {:.0?}) {girth_want:.0?} off {girth_err:.1?} mm | stature {:.1}..{:.1}/{stature_got:.1}",
            case.spine_bend,
            case.spine_twist,
            case.head_turn,
            [
                rec.result.comparison.levels.chest,
                rec.result.comparison.levels.waist,
                rec.result.comparison.levels.hip
            ],
            stature_want[0],
            stature_want[1],
        );
        eprintln!("{row}");
        let checks = [
            ("spine bend", case.spine_bend, bend, SPINE_TOLERANCE_DEG, 1),
            ("head turn", case.head_turn, head, HEAD_TOLERANCE_DEG, 2),
        ];
        for (what, want, got, tolerance, slot) in checks {
            worst[slot] = worst[slot].max((want - got).abs());
            if (want - got).abs() > tolerance {
                misses.push((i, what.to_string(), format!("{want:.1} recovered as {got:.1}")));
            }
        }
        worst[3] = worst[3].max(girth_err.iter().copied().fold(0.0, f64::max));
        worst[4] = worst[4].max(stature_err);
        if stature_err > STATURE_TOLERANCE_MM {
            let [cut, kept] = stature_want;
            let range = format!("{cut:.1} (crown cut) to {kept:.1} (crown kept)");
            misses.push((i, "stature".into(), format!("{stature_got:.1} outside {range}")));
        }
        if girth_err.iter().any(|&e| exceeds(e, GIRTH_TOLERANCE_MM))
            || exceeds(girth_mean, GIRTH_MEAN_TOLERANCE_MM)
        {
            misses.push((
                i,
                "girths".into(),
                format!("chest, waist, hip off by {girth_err:.1?} mm"),
            ));
        }
    }
    eprintln!(
        "{} cases; worst: limb {:.2} deg, spine bend {:.2} deg, head turn {:.2} deg, girth {:.1} mm, stature {:.1} mm outside its range",
        cases.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3],
        worst[4]
    );
    assert!(cases.len() >= 20);
    let misses: Vec<String> =
        misses.iter().map(|(i, w, how)| format!("case {i}: {w}: {how}")).collect();
    assert!(misses.is_empty(), "{} misses:\n{}", misses.len(), misses.join("\n"));
}

/// Issue 15, a different deformer: the sim generator's bodies (capsule limbs, no skinning)
/// standing asymmetrically, captured with a typical scanner's noise and holes, against the
/// same `BodyParams` in the symmetric A-pose captured alike: the pose-symmetric scan's chest,
/// waist and hip (at the A-pose body's levels) within 5 mm.
#[test]
fn reconstruct_straightens_the_sim_generators_asymmetric_bodies() {
    use capture_sim::{Artifacts, BodyParams, Pose as SimPose, capture, generate};
    let model = BodyModel::builtin();
    let tmp = tempfile::tempdir().unwrap();
    let scanned = |params: &BodyParams, name: &str| {
        let body = generate(params).expect("the body generates");
        let path = tmp.path().join(format!("{name}.ply"));
        let mesh = common::surface_mesh(&capture(&body, &Artifacts::typical_scanner(7)));
        std::fs::write(&path, dressform::body::scan::format::Format::Ply.encode(&mesh)).unwrap();
        load(&path)
    };
    let mut poses = Vec::new();
    let mut pose = SimPose::a_pose();
    pose.left_arm.abduction_deg += 15.0;
    pose.right_leg.abduction_deg += 5.0;
    poses.push(("left arm +15, right leg +5", pose));
    let mut pose = SimPose::a_pose();
    pose.right_arm.abduction_deg += 20.0;
    pose.right_arm.shoulder_elevation_mm = 15.0;
    pose.left_leg.abduction_deg += 6.0;
    poses.push(("right arm +20 and shrugged 15 mm, left leg +6", pose));
    let mut pose = SimPose::a_pose();
    pose.left_arm.abduction_deg += 10.0;
    pose.spine.lateral_bend_deg = 5.0;
    pose.spine.twist_deg = 8.0;
    pose.head_turn_deg = 20.0;
    poses.push(("left arm +10, spine bent 5 and twisted 8, head turned 20", pose));
    let reference = scanned(&BodyParams::default(), "a_pose");
    let at = levels(&SegmentedBody::find(&reference.body).unwrap());
    let mut misses = Vec::new();
    for (what, pose) in poses {
        let scan = scanned(&BodyParams { pose, ..BodyParams::default() }, "posed");
        let rec = reconstruct(&scan, &model, &ReconstructOptions::default(), |_| {})
            .unwrap_or_else(|e| panic!("sim body, {what}: {e}"));
        let heights = [at.chest.min(rec.result.comparison.levels.chest), at.waist, at.hip];
        let (want, got) = (
            girths(&reference.body, 0.0, &heights),
            girths(&rec.reposed.posed.body, 0.0, &heights),
        );
        let err: Vec<f64> = want.iter().zip(&got).map(|(a, b)| (a - b).abs()).collect();
        eprintln!(
            "sim body, {what}: fit {:.1} s, rms {:.2}/{:.2} mm; chest, waist, hip {want:.0?} pose-symmetric {got:.0?} off {err:.1?} mm",
            rec.reposed.fit_seconds,
            rec.reposed.fit.residuals.model_to_scan_mm,
            rec.reposed.fit.residuals.scan_to_model_mm
        );
        if err.iter().any(|&e| exceeds(e, GIRTH_TOLERANCE_MM)) {
            misses.push(format!("{what}: chest, waist and hip off by {err:.1?} mm"));
        }
    }
    assert!(misses.is_empty(), "{}", misses.join("\n"));
}
