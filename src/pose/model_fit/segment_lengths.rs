//! Limb segments' lengths as shape freedom: MakeHuman's body, and so the model's shape space
//! (eq. 2), has short upper arms (0.136 of the stature between the shoulder and elbow joints;
//! 0.186 in people, Drillis & Contini via Winter, "Biomechanics and Motor Control of Human
//! Movement"): the elbow sits 70-80 mm too high and no +-2 sd body reaches a real customer's
//! arm (`tests/pose_symmetry_proportions.rs`). So the fit gets one more shape direction per arm
//! segment (both sides alike, as people's arms are): the segment stretched along its bone, the
//! bones below it carried along, blended by the skin weights. Like the PCA components its
//! joints follow by the regressor (eq. 1), so the fit treats it as one more beta with the same
//! prior.

use crate::pose::body_model::BodyModel;
use glam::DVec3;

/// The segments, by their bone and the bone that starts where it ends (`.L` and `.R`).
pub const SEGMENTS: [(&str, &str); 2] = [("upperarm01", "lowerarm01"), ("lowerarm01", "wrist")];

/// One unit of a segment's coefficient, as a fraction of its length: the model's upper arm is
/// about 3 of these short of a real one (0.136 against 0.186 of the stature), so a real arm
/// costs what a 3 sd shape does; people's segment lengths vary by 5-8% (one standard deviation).
pub const LENGTH_STEP: f64 = 0.12;

/// `model` with one more shape direction per [`SEGMENTS`] entry (after its own components).
pub fn extended(model: &BodyModel) -> BodyModel {
    let joints = model.joints(&[]);
    let names = &model.skeleton.names;
    let parents = &model.skeleton.parents;
    let find = |n: String| names.iter().position(|b| *b == n);
    // Whether bone `l` lies below bone `b` (or is it).
    let below = |mut l: usize, b: usize| loop {
        if l == b {
            return true;
        }
        match parents[l] {
            Some(p) => l = p,
            None => return false,
        }
    };
    let mut out = model.clone();
    for (bone, child) in SEGMENTS {
        let mut field = vec![DVec3::ZERO; model.mean.len()];
        for side in [".L", ".R"] {
            let (Some(b), Some(c)) =
                (find(format!("{bone}{side}")), find(format!("{child}{side}")))
            else {
                continue;
            };
            let axis = joints[c] - joints[b];
            let length = axis.length();
            let shift = axis * LENGTH_STEP;
            for (v, f) in field.iter_mut().enumerate() {
                for (l, w) in model.weights.of(v) {
                    if l == b {
                        let t = (model.mean[v] - joints[b]).dot(axis) / (length * length);
                        *f += w * t.clamp(0.0, 1.0) * shift;
                    } else if below(l, b) {
                        *f += w * shift;
                    }
                }
            }
        }
        let norm = field.iter().map(|d| d.length_squared()).sum::<f64>().sqrt();
        out.components.push(field);
        out.sigmas.push(norm);
        out.explained.push(0.0);
    }
    out
}
