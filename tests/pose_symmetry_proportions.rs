//! Issue 15: are the sim generator's customers human, and can the body model take them? The
//! arm's segment-length ratios of stature measured alike on the generator's demo customer, on
//! the MakeHuman base and on the built-in model's mean and its +-2 sd bodies, beside the
//! anthropometric reference (Drillis & Contini, via Winter, "Biomechanics and Motor Control of
//! Human Movement", Fig. 4.1).
//!
//! What it shows (2026-12-02): the generator is human (upper arm 0.172, forearm 0.145, hand
//! 0.105 of the stature, the hanging fingertip at 0.370; Winter 0.186, 0.146, 0.108, 0.377); the
//! model is not: its upper arm is 0.132-0.143 (MakeHuman's elbow sits 70-80 mm too high) and its
//! hanging fingertip 0.417-0.435 over every +-2 sd body: no shape coefficient reaches a real arm.

use crate::common;
use dressform::pose::body_model::BodyModel;
use dressform::pose::makehuman::MakeHuman;
use glam::DVec3;

/// Winter's ratios of stature (Drillis & Contini): the segments' lengths (upper arm, forearm,
/// hand) and the fingertip's height with the arm hanging; the shoulder joint's height and the
/// distance between the shoulder joints are not in the table.
const WINTER: Proportions = Proportions {
    shoulder: f64::NAN,
    upper_arm: 0.186,
    forearm: 0.146,
    hand: 0.108,
    fingertip: 0.377,
    shoulders_apart: f64::NAN,
};

/// How far (fraction of the stature) a human-like body's arm may lie from Winter's ratios: about
/// one standard deviation of adult segment lengths (coefficients of variation of 5-8%, e.g.
/// ANSUR II's acromion-radiale and radiale-stylion lengths).
const HUMAN_TOLERANCE: f64 = 0.015;

/// An arm's proportions, as fractions of the stature: the shoulder joint's height, the
/// segments' lengths between the joint centres (the hand's to the fingertip), the fingertip's
/// height with the arm hanging straight (the shoulder joint's height less the three), and the
/// distance between the two shoulder joints.
#[derive(Debug, Clone, Copy)]
struct Proportions {
    shoulder: f64,
    upper_arm: f64,
    forearm: f64,
    hand: f64,
    fingertip: f64,
    shoulders_apart: f64,
}

/// The landmarks of one arm and the body's floor and crown.
struct Arm {
    floor: f64,
    crown: f64,
    shoulder: DVec3,
    elbow: DVec3,
    wrist: DVec3,
    fingertip: DVec3,
    other_shoulder: DVec3,
}

impl Arm {
    fn proportions(&self) -> Proportions {
        let h = self.crown - self.floor;
        let upper_arm = self.shoulder.distance(self.elbow) / h;
        let forearm = self.elbow.distance(self.wrist) / h;
        let hand = self.wrist.distance(self.fingertip) / h;
        let shoulder = (self.shoulder.z - self.floor) / h;
        Proportions {
            shoulder,
            upper_arm,
            forearm,
            hand,
            fingertip: shoulder - upper_arm - forearm - hand,
            shoulders_apart: self.shoulder.distance(self.other_shoulder) / h,
        }
    }
}

/// A model-topology body's left arm: the model's joints and the hand vertex farthest from the
/// wrist.
fn model_arm(model: &BodyModel, vertices: &[DVec3]) -> Arm {
    let joints = model.regress_joints(vertices);
    let bone = |n: &str| model.skeleton.names.iter().position(|b| b == n).unwrap();
    let wrist = joints[bone("wrist.L")];
    let hand = bone("wrist.L");
    let fingertip = (0..vertices.len())
        .filter(|&v| model.weights.of(v).any(|(b, w)| b == hand && w > 0.5))
        .map(|v| vertices[v])
        .max_by(|a, b| a.distance(wrist).total_cmp(&b.distance(wrist)))
        .unwrap();
    let z = |f: fn(f64, f64) -> f64, init| vertices.iter().map(|p| p.z).fold(init, f);
    let shoulder = joints[bone("upperarm01.L")];
    Arm {
        floor: z(f64::min, f64::INFINITY),
        crown: z(f64::max, f64::NEG_INFINITY),
        shoulder,
        elbow: joints[bone("lowerarm01.L")],
        wrist,
        fingertip,
        other_shoulder: joints[bone("upperarm01.R")],
    }
}

fn row(name: &str, p: &Proportions) -> String {
    format!(
        "{name:<30} {:>8.3} {:>9.3} {:>8.3} {:>6.3} {:>9.3} {:>9.3}",
        p.shoulder, p.upper_arm, p.forearm, p.hand, p.fingertip, p.shoulders_apart
    )
}

#[test]
fn the_generators_arms_and_the_models_are_measured_alike() {
    use capture_sim::{BodyParams, generate};
    let model = BodyModel::builtin();
    let mut rows = vec![format!(
        "{:<30} {:>8} {:>9} {:>8} {:>6} {:>9} {:>9}",
        "fractions of stature",
        "shoulder",
        "upper arm",
        "forearm",
        "hand",
        "fingertip",
        "shoulders"
    )];
    rows.push(row("Winter (Drillis & Contini)", &WINTER));
    let customer = generate(&BodyParams::default()).unwrap();
    let (l, r) = (&customer.truth.landmarks.left, &customer.truth.landmarks.right);
    let v = |a: [f64; 3]| DVec3::from_array(a);
    let generator = Arm {
        floor: 0.0,
        crown: customer.truth.height_mm,
        shoulder: v(l.shoulder_joint),
        elbow: v(l.elbow_joint),
        wrist: v(l.wrist_joint),
        fingertip: v(l.fingertip),
        other_shoulder: v(r.shoulder_joint),
    };
    rows.push(row("sim generator, demo customer", &generator.proportions()));
    if let Some(dir) = common::makehuman() {
        let mh = MakeHuman::load(&dir).unwrap();
        let base = mh.base.skin(&mh.base.vertices);
        rows.push(row("MakeHuman base", &model_arm(&model, &base.positions).proportions()));
    }
    rows.push(row("model mean", &model_arm(&model, &model.mean).proportions()));
    for k in 0..model.k() {
        for s in [-2.0, 2.0] {
            let mut beta = vec![0.0; model.k()];
            beta[k] = s;
            let name = format!("model beta[{k}] = {s:+}");
            rows.push(row(&name, &model_arm(&model, &model.shape(&beta)).proportions()));
        }
    }
    eprintln!("{}", rows.join("\n"));
    // The generator is human: every segment and the hanging fingertip within this of Winter's.
    let g = generator.proportions();
    let off = [
        g.upper_arm - WINTER.upper_arm,
        g.forearm - WINTER.forearm,
        g.hand - WINTER.hand,
        g.fingertip - WINTER.fingertip,
    ];
    assert!(
        off.iter().all(|d| d.abs() <= HUMAN_TOLERANCE),
        "the generator's arm is off Winter's by {off:.3?} of the stature"
    );
}
