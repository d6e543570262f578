//! Issue 35: the mannequin on bodies unlike the demo. MakeHuman bodies drawn over gender,
//! weight, muscle, stature (1.55-1.95 m) and proportions, a quarter of them with broad, level
//! shoulders; posed with MakeHuman's own 163-bone rig, slightly asymmetric (20) or in harder
//! stances (20: both arms hanging, one arm near horizontal, one of each, the spine twisted, the
//! legs together); re-meshed by marching cubes, 1 mm of noise, holes under the arms and below
//! the crotch, the crown cut; through `reconstruct`. Each mannequin is checked against the same
//! body un-posed, its true shape: girths at the true body's chest, waist and hip levels, the
//! width jump over the whole height, self-intersections, the legs' axes.
//!
//! The acceptance is asserted as a ratchet ([`KNOWN_MISSES`]): what misses it today is
//! listed, anything else fails, and a listed miss that now holds must be taken off.
//!
//! `DRESSFORM_POPULATION=N` runs the first N of the 40, `DRESSFORM_POPULATION=35,20` the listed
//! ones (one body: `35,`; the population's bias is checked only on all 40);
//! `DRESSFORM_POPULATION_DIAG=1` also reconstructs each body scanned un-posed;
//! `DRESSFORM_LOOK=<dir>` writes each body's scan, pose-symmetric scan, truth and mannequin as
//! OBJ for `../shared/tools/look.py`.

use crate::common;
use common::Cuts;
use common::frontal::abduction;
use common::makehuman_scan::{
    girths, hole_sites, load, pose_of, posed, remesh, remesher, scanned, write_obj,
};
use common::quality::{self_intersecting_pairs, width_jump};
use dressform::body::scan::{Scan, from_mesh, read_mesh};
use dressform::body::segmented_body::SegmentedBody;
use dressform::pose::body_model::BodyModel;
use dressform::pose::body_model::population;
use dressform::pose::makehuman::MakeHuman;
use dressform::run::reconstruct::{ReconstructOptions, reconstruct};
use dressform::shape::mannequin::Layer;
use dressform::shape::measure::levels;
use glam::DVec3;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The scanner: 1 mm of noise; a body scanner's mesh resolution (mm); the crown cut
/// this far in (a scanner sees no crown). The soles stay (cut, they would move the floor).
const NOISE_MM: f64 = 1.0;
const PITCH_MM: f64 = 5.0;
const SCANNER: Cuts = Cuts { soles_mm: 0.0, crown_mm: 15.0 };
/// The statures (mm).
const STATURE_MM: (f64, f64) = (1550.0, 1950.0);
/// The population's seed: not the built-in model's (1) nor the body-model tests' (2024, 777777).
const SEED: u64 = 35;
/// How many bodies the issue asks for, half slightly posed and half in hard stances.
const BODIES: usize = 40;

/// The acceptance: chest, waist and hip at the un-posed body's levels within these
/// (mm) on the slightly posed bodies and on the hard stances;
const GIRTH_TOLERANCE_MM: [f64; 2] = [5.0, 10.0];
/// no sign bias: each girth's mean error over the population within this (mm);
const BIAS_TOLERANCE_MM: f64 = 2.0;
/// the width of the mannequin never jumping more than this between sections 2 mm apart (mm);
const WIDTH_JUMP_MM: f64 = 15.0;
/// both legs' axes within this of vertical (degrees, the default straight legs).
const LEG_AXIS_DEG: f64 = 1.0;
/// The ratchet's hysteresis (mm or degrees): a miss not listed counts only when beyond its
/// tolerance by this much, a listed one as mended only when within it by this much, so that a
/// value at the tolerance (a Python library re-meshing a hair differently) flaps neither way.
/// Today nothing is listed; the slight bodies' worst chest lies at 4.9 mm (its tolerance 5) and
/// the largest width jump at 14.6 mm (its limit 15).
const RATCHET_MARGIN: f64 = 0.5;

/// What the acceptance checks on each body, and on the population's mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Check {
    Reconstructs,
    Chest,
    Waist,
    Hip,
    WidthJump,
    Intersections,
    Legs,
    ChestBias,
    WaistBias,
    HipBias,
}

/// The acceptance's misses today, as (body, check); a bias check is keyed by [`BODIES`] and
/// checked only when all of them run. The test fails on a miss not listed and on a listed one
/// that now holds ([`RATCHET_MARGIN`] either way): the list only shrinks, and each mend must
/// take its entries off.
const KNOWN_MISSES: &[(usize, Check)] = &[];

/// The stances of the population.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stance {
    /// One arm 10-20 degrees further out with its clavicle 3-8 up, the other leg 3-8 out, the
    /// spine bent 3-6 sideways, the head turned 10-25.
    Slight,
    /// Both arms 0-5 degrees from hanging.
    ArmsDown,
    /// One arm 80-90 degrees from hanging (near horizontal).
    ArmUp,
    /// One arm 0-5, the other 80-90.
    ArmsApart,
    /// The spine twisted 10 degrees.
    Twist,
    /// The legs together: the thighs turned in by most of the rest stance.
    LegsTogether,
}

/// One body of the population: its shape, its pose, and what it is.
struct Body {
    index: usize,
    stance: Stance,
    recipe: Vec<(String, f64)>,
    pose: Vec<(String, DVec3)>,
    /// What the pose is, for the table.
    summary: String,
}

/// The side's outward turn about Y: the left limbs turn out about -Y, the right about +Y.
fn outward(side: &str) -> f64 {
    if side == ".L" { -1.0 } else { 1.0 }
}

/// The recipe of body `index` with its stature set to `stature` (mm) by MakeHuman's height
/// targets, which scale with each macro target's weight as MakeHuman's slider does.
fn with_stature(mh: &MakeHuman, recipe: &[(&str, f64)], stature: f64) -> Vec<(String, f64)> {
    let base: Vec<(String, f64)> = recipe
        .iter()
        .filter(|(t, _)| !t.starts_with("macrodetails/height/"))
        .map(|(t, w)| (t.to_string(), *w))
        .collect();
    let with = |t: f64| {
        let mut r = base.clone();
        let end = if t < 0.0 { "minheight" } else { "maxheight" };
        for (target, w) in &base {
            if let Some(rest) = target.strip_prefix("macrodetails/universal-") {
                r.push((format!("macrodetails/height/{rest}-{end}"), w * t.abs()));
            }
        }
        r
    };
    let height = |r: &[(String, f64)]| {
        let refs: Vec<(&str, f64)> = r.iter().map(|(t, w)| (t.as_str(), *w)).collect();
        let b = mh.base.skin(&mh.shaped(&refs).unwrap()).bounds().unwrap();
        b.max.z - b.min.z
    };
    let h0 = height(&base);
    let end = if stature < h0 { -1.0 } else { 1.0 };
    let t = ((stature - h0) / (height(&with(end)) - h0) * end).clamp(0.0, 1.0) * end;
    with(t)
}

/// Body `index` of the population (`population` drawn once for all).
fn body(mh: &MakeHuman, population: &population::Population, index: usize) -> Body {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED * 1000 + index as u64);
    let stance = if index < BODIES / 2 {
        Stance::Slight
    } else {
        [Stance::ArmsDown, Stance::ArmUp, Stance::ArmsApart, Stance::Twist, Stance::LegsTogether]
            [index % 5]
    };
    let mut recipe: Vec<(&str, f64)> = population.recipe(index);
    // Every fourth body broad-shouldered, level and V-shaped: the bodies that showed boxes.
    if index % 4 == 1 {
        let broad = [
            ("measure/measure-shoulder-dist-incr", rng.random_range(0.5..1.0)),
            ("torso/torso-vshape-incr", rng.random_range(0.3..0.8)),
        ];
        recipe.retain(|(t, _)| !t.contains("shoulder-dist") && !t.contains("torso-vshape"));
        recipe.extend(broad);
    }
    let recipe = with_stature(mh, &recipe, rng.random_range(STATURE_MM.0..STATURE_MM.1));

    // Rest angles of this body (MakeHuman's rest: the arms about 40 degrees from hanging).
    let refs: Vec<(&str, f64)> = recipe.iter().map(|(t, w)| (t.as_str(), *w)).collect();
    let shaped = mh.shaped(&refs).unwrap();
    let heads = mh.rig.bone_heads(&shaped);
    let joint = |name: &str| heads[mh.rig.bone(name).unwrap()];
    let arm_rest = |side: &str| {
        abduction(joint(&format!("upperarm01{side}")), joint(&format!("lowerarm01{side}")))
    };
    let leg_rest = |side: &str| {
        abduction(joint(&format!("upperleg01{side}")), joint(&format!("lowerleg01{side}")))
    };
    let (one, other) = if rng.random_bool(0.5) { (".L", ".R") } else { (".R", ".L") };
    let turn_out = |bone: &str, side: &str, deg: f64| {
        (format!("{bone}{side}"), DVec3::Y * outward(side) * deg.to_radians())
    };
    let arm_to =
        |side: &str, from_hanging: f64| turn_out("upperarm01", side, from_hanging - arm_rest(side));
    let sign: f64 = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let mut pose = Vec::new();
    let summary = match stance {
        Stance::Slight => {
            let (arm, clavicle, leg) = (
                rng.random_range(10.0..20.0),
                rng.random_range(3.0..8.0),
                rng.random_range(3.0..8.0),
            );
            let (bend, head): (f64, f64) =
                (rng.random_range(3.0..6.0) * sign, rng.random_range(10.0..25.0));
            pose.push(turn_out("upperarm01", one, arm));
            pose.push(turn_out("clavicle", one, clavicle));
            pose.push(turn_out("upperleg01", other, leg));
            for bone in ["spine03", "spine02"] {
                pose.push((bone.to_string(), DVec3::Y * (bend / 2.0).to_radians()));
            }
            pose.push(("head".to_string(), DVec3::Z * (head * sign).to_radians()));
            format!(
                "arm{one} +{arm:.0} clav +{clavicle:.0} leg{other} +{leg:.0} bend {bend:+.0} head {:+.0}",
                head * sign
            )
        }
        Stance::ArmsDown => {
            let (a, b) = (rng.random_range(0.0..5.0), rng.random_range(0.0..5.0));
            pose.extend([arm_to(".L", a), arm_to(".R", b)]);
            format!("arms at {a:.0}/{b:.0} from hanging")
        }
        Stance::ArmUp => {
            let a = rng.random_range(80.0..90.0);
            pose.push(arm_to(one, a));
            format!("arm{one} at {a:.0} from hanging")
        }
        Stance::ArmsApart => {
            let (a, b) = (rng.random_range(0.0..5.0), rng.random_range(80.0..90.0));
            pose.extend([arm_to(one, a), arm_to(other, b)]);
            format!("arm{one} at {a:.0}, arm{other} at {b:.0} from hanging")
        }
        Stance::Twist => {
            let twist = 10.0 * sign;
            for bone in ["spine03", "spine02"] {
                pose.push((bone.to_string(), DVec3::Z * (twist / 2.0).to_radians()));
            }
            format!("spine twist {twist:+.0}")
        }
        Stance::LegsTogether => {
            // In by most of the rest stance: the thighs touch, the shins stay apart.
            let share = rng.random_range(0.7..0.9);
            for side in [".L", ".R"] {
                pose.push(turn_out("upperleg01", side, -share * leg_rest(side)));
            }
            format!("legs in by {:.0}% of rest", share * 100.0)
        }
    };
    Body { index, stance, recipe, pose, summary }
}

/// The indices this run checks: all 40, the first N with `DRESSFORM_POPULATION=N`, or the
/// listed ones with `DRESSFORM_POPULATION=35,20` (one body: `35,`).
fn chosen() -> Vec<usize> {
    let Ok(value) = std::env::var("DRESSFORM_POPULATION") else { return (0..BODIES).collect() };
    let number = |s: &str| -> usize {
        s.trim().parse().unwrap_or_else(|_| panic!("DRESSFORM_POPULATION: {s:?} is not a number"))
    };
    if !value.contains(',') {
        return (0..number(&value).min(BODIES)).collect();
    }
    let mut listed: Vec<usize> =
        value.split(',').filter(|s| !s.trim().is_empty()).map(number).collect();
    listed.sort_unstable();
    listed.dedup();
    assert!(
        !listed.is_empty() && listed.iter().all(|&i| i < BODIES),
        "DRESSFORM_POPULATION={value}: list bodies 0-{}",
        BODIES - 1
    );
    listed
}

/// A leg's axis angles from vertical (degrees): sideways (x) and forwards (y), by a least-
/// squares line through its layers' centres.
fn leg_axis(layers: &[Layer]) -> [f64; 2] {
    let n = layers.len() as f64;
    let mean = |f: &dyn Fn(&Layer) -> f64| layers.iter().map(f).sum::<f64>() / n;
    let mz = mean(&|l| l.z);
    let szz: f64 = layers.iter().map(|l| (l.z - mz).powi(2)).sum();
    [0, 1].map(|k| {
        let mc = mean(&|l| l.centre[k]);
        let szc: f64 = layers.iter().map(|l| (l.z - mz) * (l.centre[k] - mc)).sum();
        (szc / szz).atan().to_degrees()
    })
}

/// What one body gave.
struct Row {
    index: usize,
    stance: Stance,
    line: String,
    /// Chest, waist and hip error (mm, mannequin minus truth at the truth's levels).
    girth_error: [f64; 3],
    width_jump: f64,
    intersections: usize,
    legs_deg: f64,
    failed: Option<String>,
}

/// The truth: the body un-posed, clean, in the canonical frame.
fn truth(mh: &MakeHuman, body: &Body) -> Scan {
    let refs: Vec<(&str, f64)> = body.recipe.iter().map(|(t, w)| (t.as_str(), *w)).collect();
    let skin = posed(mh, &mh.shaped(&refs).unwrap(), &[]);
    from_mesh(skin, Path::new("truth"), &Default::default()).unwrap()
}

fn check(
    mh: &MakeHuman,
    model: &BodyModel,
    body: &Body,
    scan: &Scan,
    rest: Option<&Scan>,
    look: Option<&Path>,
) -> Row {
    let truth = truth(mh, body);
    let segmented = SegmentedBody::find(&truth.body).unwrap();
    let marks = segmented.landmarks();
    let at = levels(&segmented);
    let z = [at.chest, at.waist, at.hip];
    let want = girths(&truth.body, 0.0, &z);
    let mut row = Row {
        index: body.index,
        stance: body.stance,
        line: format!(
            "{:2} {:<12} {:>4.0} mm {:<52}",
            body.index,
            format!("{:?}", body.stance),
            marks.height,
            body.summary
        ),
        girth_error: [f64::NAN; 3],
        width_jump: f64::NAN,
        intersections: 0,
        legs_deg: f64::NAN,
        failed: None,
    };
    let options = ReconstructOptions::default();
    let rec = match reconstruct(scan, model, &options, |_| {}) {
        Ok(rec) => rec,
        Err(e) => {
            row.failed = Some(e.to_string());
            return row;
        }
    };
    let m = &rec.result.mannequin;
    let got = girths(&m.mesh, m.axis, &z);
    let posed = girths(&rec.reposed.posed.body, m.axis, &z);
    let own = m.own_landmarks();
    let d_crotch = own.crotch - marks.crotch;
    let shifted: Vec<f64> = z.iter().map(|z| z + d_crotch).collect();
    let got_shifted = girths(&m.mesh, m.axis, &shifted);
    for k in 0..3 {
        row.girth_error[k] = got[k] - want[k];
    }
    row.width_jump = width_jump(&m.mesh, f64::NEG_INFINITY, f64::INFINITY).0;
    row.intersections = self_intersecting_pairs(&m.mesh).len();
    let legs = [leg_axis(&m.left_leg), leg_axis(&m.right_leg)];
    row.legs_deg = legs.iter().flatten().fold(0.0_f64, |a, b| a.max(b.abs()));
    let diff = |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(a, b)| a - b).collect() };
    row.line += &format!(
        " | truth {want:.0?} err {:+.1?} posed {:+.1?} at-crotch {:+.1?} | dcrotch {d_crotch:+.1} posed {:+.1} darmpit {:+.1} | jump {:.1} x {} legs {:.1?}",
        row.girth_error,
        diff(&posed, &want),
        diff(&got_shifted, &want),
        rec.result.regions.landmarks.crotch - marks.crotch,
        own.left_armpit.min(own.right_armpit) - marks.left_armpit.min(marks.right_armpit),
        row.width_jump,
        row.intersections,
        legs,
    );
    if let Some(rest) = rest {
        // G_tn: the un-posed body scanned; its pipeline's pose-symmetric scan and mannequin.
        let scanned = girths(&rest.body, 0.0, &z);
        row.line += &format!(" | rest: scan {:+.1?}", diff(&scanned, &want));
        match reconstruct(rest, model, &options, |_| {}) {
            Ok(r) => {
                let m = &r.result.mannequin;
                row.line += &format!(
                    " posed {:+.1?} mannequin {:+.1?} darmpit {:+.1}",
                    diff(&girths(&r.reposed.posed.body, m.axis, &z), &want),
                    diff(&girths(&m.mesh, m.axis, &z), &want),
                    {
                        let own = m.own_landmarks();
                        own.left_armpit.min(own.right_armpit)
                            - marks.left_armpit.min(marks.right_armpit)
                    }
                );
            }
            Err(e) => row.line += &format!(" failed: {e}"),
        }
    }
    if let Some(dir) = look {
        write_obj(&truth.body, &dir.join(format!("body{:02}-truth.obj", body.index)));
        write_obj(&m.mesh, &dir.join(format!("body{:02}-mannequin.obj", body.index)));
        let reposed = &rec.reposed.posed.body;
        write_obj(reposed, &dir.join(format!("body{:02}-reposed.obj", body.index)));
    }
    row
}

/// Scan files of every `(body, "posed" or "rest")` job: the skin posed (or at rest),
/// re-meshed (two Python runs side by side), with the scanner's noise, holes and cuts.
fn scan_all(mh: &MakeHuman, python: &str, tmp: &Path, jobs: &[(&Body, &str)]) -> Vec<PathBuf> {
    let name = |b: &Body, tag: &str, ext: &str| tmp.join(format!("{tag}{}.{ext}", b.index));
    let floors: Vec<(f64, [DVec3; 3])> = jobs
        .iter()
        .map(|(b, tag)| {
            let refs: Vec<(&str, f64)> = b.recipe.iter().map(|(t, w)| (t.as_str(), *w)).collect();
            let shaped = mh.shaped(&refs).unwrap();
            let bones = if *tag == "posed" { &b.pose[..] } else { &[] };
            let skin = posed(mh, &shaped, bones);
            write_obj(&skin, &name(b, tag, "obj"));
            let heads = mh.rig.bone_heads(&mh.pose(&shaped, &pose_of(bones)).unwrap());
            (skin.bounds().unwrap().min.z, hole_sites(mh, &heads))
        })
        .collect();
    let pairs: Vec<_> =
        jobs.iter().map(|(b, tag)| (name(b, tag, "obj"), name(b, tag, "ply"))).collect();
    std::thread::scope(|s| {
        for chunk in pairs.chunks(pairs.len().div_ceil(2)) {
            s.spawn(|| remesh(python, PITCH_MM, chunk));
        }
    });
    jobs.par_iter()
        .zip(&floors)
        .map(|((b, tag), (floor, holes))| {
            let remeshed = read_mesh(&name(b, tag, "ply")).unwrap().0;
            let mut rng = ChaCha8Rng::seed_from_u64(SEED * 2000 + b.index as u64);
            let mesh = scanned(&remeshed, *floor, holes, SCANNER, NOISE_MM, &mut rng);
            let path = tmp.join(format!("{tag}-scan{}.obj", b.index));
            write_obj(&mesh, &path);
            path
        })
        .collect()
}

#[test]
fn mannequins_of_varied_bodies_match_their_unposed_truth() {
    let Some(dir) = common::makehuman() else { return };
    let Some(python) = remesher() else { return };
    let mh = MakeHuman::load(&dir).expect("the MakeHuman assets load");
    let model = BodyModel::builtin();
    let population = population::sample(BODIES, SEED);
    let bodies: Vec<Body> = chosen().into_iter().map(|i| body(&mh, &population, i)).collect();
    let tmp = tempfile::tempdir().unwrap();
    let look = std::env::var_os("DRESSFORM_LOOK").map(std::path::PathBuf::from);
    if let Some(dir) = &look {
        std::fs::create_dir_all(dir).unwrap();
    }

    // With `DRESSFORM_POPULATION_DIAG=1` each body is also scanned un-posed, to tell the
    // scanner's and the pipeline's errors from the pose's.
    let diagnose = std::env::var_os("DRESSFORM_POPULATION_DIAG").is_some();
    let mut jobs: Vec<(&Body, &str)> = bodies.iter().map(|b| (b, "posed")).collect();
    if diagnose {
        jobs.extend(bodies.iter().map(|b| (b, "rest")));
    }
    let scans = scan_all(&mh, &python, tmp.path(), &jobs);
    if let Some(dir) = &look {
        for ((b, tag), path) in jobs.iter().zip(&scans) {
            std::fs::copy(path, dir.join(format!("body{:02}-{tag}-scan.obj", b.index))).unwrap();
        }
    }
    let rows: Vec<Row> = bodies
        .par_iter()
        .enumerate()
        .map(|(k, b)| {
            let rest = diagnose.then(|| load(&scans[bodies.len() + k]));
            let row = check(&mh, &model, b, &load(&scans[k]), rest.as_ref(), look.as_deref());
            eprintln!("{}", row.line);
            row
        })
        .collect();

    eprintln!("\n{} bodies", rows.len());
    for r in &rows {
        let how = r.failed.as_deref().unwrap_or("");
        eprintln!("{}{}", r.line, how);
    }
    for (name, family) in [("slight", true), ("hard", false)] {
        let errors: Vec<&Row> = rows
            .iter()
            .filter(|r| (r.stance == Stance::Slight) == family && r.failed.is_none())
            .collect();
        let n = errors.len() as f64;
        let mean = |k: usize| errors.iter().map(|r| r.girth_error[k]).sum::<f64>() / n;
        let worst = |k: usize| errors.iter().map(|r| r.girth_error[k].abs()).fold(0.0, f64::max);
        eprintln!(
            "{name}: {} reconstructed; chest, waist, hip mean {:+.1} {:+.1} {:+.1} worst {:.1} {:.1} {:.1} mm; width jump worst {:.1}; intersections {}; legs worst {:.1} deg",
            errors.len(),
            mean(0),
            mean(1),
            mean(2),
            worst(0),
            worst(1),
            worst(2),
            errors.iter().map(|r| r.width_jump).fold(0.0, f64::max),
            errors.iter().map(|r| r.intersections).sum::<usize>(),
            errors.iter().map(|r| r.legs_deg).fold(0.0, f64::max),
        );
    }

    let run: Vec<usize> = rows.iter().map(|r| r.index).collect();
    let found = misses(&rows, -RATCHET_MARGIN);
    let holding = misses(&rows, RATCHET_MARGIN);
    let known: Vec<(usize, Check)> = KNOWN_MISSES
        .iter()
        .filter(|(i, _)| run.contains(i) || run.len() == BODIES)
        .copied()
        .collect();
    let new: Vec<_> = found.iter().filter(|m| !known.contains(m)).collect();
    let mended: Vec<_> = known.iter().filter(|m| !holding.contains(m)).collect();
    assert!(
        new.is_empty() && mended.is_empty(),
        "issue 35's acceptance: new misses {new:?}; mended, take them off KNOWN_MISSES: {mended:?}"
    );
}

/// The acceptance's misses over `rows`, each tolerance tightened by `margin` (loosened where
/// it is negative).
fn misses(rows: &[Row], margin: f64) -> Vec<(usize, Check)> {
    let mut out = Vec::new();
    for r in rows {
        if r.failed.is_some() {
            out.push((r.index, Check::Reconstructs));
            continue;
        }
        let tolerance = GIRTH_TOLERANCE_MM[usize::from(r.stance != Stance::Slight)] - margin;
        for (k, check) in [Check::Chest, Check::Waist, Check::Hip].into_iter().enumerate() {
            if r.girth_error[k].abs() > tolerance {
                out.push((r.index, check));
            }
        }
        if r.width_jump > WIDTH_JUMP_MM - margin {
            out.push((r.index, Check::WidthJump));
        }
        if r.intersections > 0 {
            out.push((r.index, Check::Intersections));
        }
        if r.legs_deg > LEG_AXIS_DEG - margin {
            out.push((r.index, Check::Legs));
        }
    }
    if rows.len() < BODIES {
        return out;
    }
    let built: Vec<&Row> = rows.iter().filter(|r| r.failed.is_none()).collect();
    for (k, check) in [Check::ChestBias, Check::WaistBias, Check::HipBias].into_iter().enumerate() {
        let mean = built.iter().map(|r| r.girth_error[k]).sum::<f64>() / built.len() as f64;
        if mean.abs() > BIAS_TOLERANCE_MM - margin {
            out.push((BODIES, check));
        }
    }
    out
}
