//! A sampled population of adult MakeHuman bodies (the data for the PCA, eq. 2): macro sliders
//! (gender, muscle, weight, height, proportions) turned into target weights with MakeHuman's
//! rules, plus measure and regional targets (bust, waist, hips, torso, stomach, buttocks, ...)
//! and the apparel body shapes (`bodyshapes/`). Never the asymmetric targets (`asym/`, one-sided
//! `armslegs/`). Age is fixed at MakeHuman's "young" (25 years): the assets carry the height
//! and proportion targets for that age only.
//!
//! The regional spreads follow MakeHuman's own randomizer (`plugins/0_modeling_8_random.py`,
//! `randomize()` and `getRandomValue()`): the body groups (torso, hip, stomach, buttocks) are
//! normal around their default with sigma = 0.1 of the slider's range; the `measure` group is
//! not randomized there at all (it exists to dial in a measured body), so it gets half that
//! spread here; pregnancy is zeroed for men and for women younger than about 57 years
//! ("No pregnancy for male, too young or too old subjects"), hence never sampled at our age.
//! The body shapes are the apparel classification (hourglass, triangle, inverted triangle,
//! rectangle, apple, diamond, column, trapezoid: the shapes garment sizing sorts bodies into);
//! every body leans towards one of its gender's shapes by a uniform amount. The "glandular"
//! types of the same asset set (adrenal, gonadal, liver, ovary, thyroid, after a diet book's
//! body types) are left out: they are caricatures that move the skin 55-98 mm at full weight
//! (the apparel shapes 12-29 mm) and, each used by about 1 body in 30, they are variance no 15
//! components capture (they made most of the held-out errors above 20 mm).

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};

/// The three levels of a macro slider in [0, 1] (0.5 = average): MakeHuman's weights of its
/// `min`, `average` and `max` targets (`humanmodifier.py`: linear between the levels).
fn levels(x: f64) -> [f64; 3] {
    [(1.0 - 2.0 * x).max(0.0), 1.0 - (2.0 * x - 1.0).abs(), (2.0 * x - 1.0).max(0.0)]
}

const GENDERS: [&str; 2] = ["female", "male"];
const MUSCLE: [&str; 3] = ["minmuscle", "averagemuscle", "maxmuscle"];
const WEIGHT: [&str; 3] = ["minweight", "averageweight", "maxweight"];

/// Measure targets as `(decrease, increase)` pairs: one slider in [-1, 1] each.
const MEASURE: [(&str, &str); 20] = [
    ("measure/measure-bust-circ-decr", "measure/measure-bust-circ-incr"),
    ("measure/measure-underbust-circ-decr", "measure/measure-underbust-circ-incr"),
    ("measure/measure-waist-circ-decr", "measure/measure-waist-circ-incr"),
    ("measure/measure-hips-circ-decr", "measure/measure-hips-circ-incr"),
    ("measure/measure-thigh-circ-decr", "measure/measure-thigh-circ-incr"),
    ("measure/measure-neck-circ-decr", "measure/measure-neck-circ-incr"),
    ("measure/measure-upperarm-circ-decr", "measure/measure-upperarm-circ-incr"),
    ("measure/measure-calf-circ-decr", "measure/measure-calf-circ-incr"),
    ("measure/measure-knee-circ-decr", "measure/measure-knee-circ-incr"),
    ("measure/measure-ankle-circ-decr", "measure/measure-ankle-circ-incr"),
    ("measure/measure-wrist-circ-decr", "measure/measure-wrist-circ-incr"),
    ("measure/measure-frontchest-dist-decr", "measure/measure-frontchest-dist-incr"),
    ("measure/measure-shoulder-dist-decr", "measure/measure-shoulder-dist-incr"),
    ("measure/measure-napetowaist-dist-decr", "measure/measure-napetowaist-dist-incr"),
    ("measure/measure-waisttohip-dist-decr", "measure/measure-waisttohip-dist-incr"),
    ("measure/measure-neck-height-decr", "measure/measure-neck-height-incr"),
    ("measure/measure-upperarm-length-decr", "measure/measure-upperarm-length-incr"),
    ("measure/measure-lowerarm-length-decr", "measure/measure-lowerarm-length-incr"),
    ("measure/measure-upperleg-height-decr", "measure/measure-upperleg-height-incr"),
    ("measure/measure-lowerleg-height-decr", "measure/measure-lowerleg-height-incr"),
];

/// Regional targets (MakeHuman's body groups) as `(decrease, increase)` pairs; not
/// `stomach-pregnant` (see the module's notes).
const REGIONAL: [(&str, &str); 9] = [
    ("torso/torso-scale-depth-decr", "torso/torso-scale-depth-incr"),
    ("torso/torso-scale-horiz-decr", "torso/torso-scale-horiz-incr"),
    ("torso/torso-vshape-decr", "torso/torso-vshape-incr"),
    ("torso/torso-muscle-pectoral-decr", "torso/torso-muscle-pectoral-incr"),
    ("hip/hip-scale-depth-decr", "hip/hip-scale-depth-incr"),
    ("hip/hip-scale-horiz-decr", "hip/hip-scale-horiz-incr"),
    ("hip/hip-waist-down", "hip/hip-waist-up"),
    ("stomach/stomach-tone-decr", "stomach/stomach-tone-incr"),
    ("buttocks/buttocks-volume-decr", "buttocks/buttocks-volume-incr"),
];

/// The apparel body shapes: `bodyshapes/bodyshapes-elvs-<fem|man>-<name>`.
const FEMALE_SHAPES: [&str; 8] = [
    "apple",
    "diamond",
    "full-hourglass",
    "invert-triangle",
    "lean-column",
    "neat-hourglass",
    "rectangle",
    "triangle",
];
const MALE_SHAPES: [&str; 6] =
    ["apple", "invert-triangle", "lean-column", "rectangle", "trapezoid", "triangle"];

/// The spread of the macro sliders (standard deviations on [0, 1], around 0.5): chosen so
/// the population spans MakeHuman's adult range without piling up at the ends.
const MUSCLE_SD: f64 = 0.15;
const WEIGHT_SD: f64 = 0.2;
const HEIGHT_SD: f64 = 0.1;
/// Proportions from "uncommon" (0) to "ideal" (1), uniform over this range.
const PROPORTIONS: (f64, f64) = (0.3, 1.0);
/// How far from pure female (0) or male (1) a body's gender slider lies, at most.
const GENDER_BLEND: f64 = 0.15;
/// Regional sliders: normal with MakeHuman's randomizer spread (sigma = 0.1 of the range
/// [-1, 1]), clipped to [-1, 1].
const REGIONAL_SD: f64 = 0.2;
/// Measure sliders: half the regional spread (MakeHuman's randomizer leaves them at 0).
const MEASURE_SD: f64 = 0.1;
/// The weight of a body's shape: uniform below this (a full-weight shape is a caricature).
const SHAPE_WEIGHT: f64 = 0.6;

/// Bodies as weights over a fixed list of targets.
#[derive(Debug, Clone, PartialEq)]
pub struct Population {
    /// Target names (relative to `targets/`, no extension).
    pub targets: Vec<String>,
    /// Per body, one weight per target.
    pub bodies: Vec<Vec<f64>>,
}

/// Every target a body can use, in the order of the weights.
pub fn target_names() -> Vec<String> {
    let mut names = Vec::new();
    for g in GENDERS {
        for m in MUSCLE {
            for w in WEIGHT {
                names.push(format!("macrodetails/universal-{g}-young-{m}-{w}"));
                for h in ["minheight", "maxheight"] {
                    names.push(format!("macrodetails/height/{g}-young-{m}-{w}-{h}"));
                }
                for p in ["uncommonproportions", "idealproportions"] {
                    names.push(format!("macrodetails/proportions/{g}-young-{m}-{w}-{p}"));
                }
            }
        }
    }
    for (decr, incr) in MEASURE.iter().chain(&REGIONAL) {
        names.extend([decr.to_string(), incr.to_string()]);
    }
    names.extend(FEMALE_SHAPES.iter().map(|s| format!("bodyshapes/bodyshapes-elvs-fem-{s}")));
    names.extend(MALE_SHAPES.iter().map(|s| format!("bodyshapes/bodyshapes-elvs-man-{s}")));
    names
}

/// `count` bodies drawn with the seeded generator `seed` (ChaCha8: the same on every platform).
pub fn sample(count: usize, seed: u64) -> Population {
    let targets = target_names();
    let index = |name: &str| targets.iter().position(|t| t == name).unwrap_or(usize::MAX);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let slider = |sd: f64, rng: &mut ChaCha8Rng| {
        Normal::new(0.5, sd).map_or(0.5, |n| n.sample(rng)).clamp(0.0, 1.0)
    };
    let bodies = (0..count)
        .map(|_| {
            let mut w = vec![0.0; targets.len()];
            let male = rng.random_bool(0.5);
            let blend = rng.random_range(0.0..GENDER_BLEND);
            let gender = if male { 1.0 - blend } else { blend };
            let muscle = levels(slider(MUSCLE_SD, &mut rng));
            let weight = levels(slider(WEIGHT_SD, &mut rng));
            let height = levels(slider(HEIGHT_SD, &mut rng));
            let proportions = levels(rng.random_range(PROPORTIONS.0..PROPORTIONS.1));
            for (gi, g) in GENDERS.iter().enumerate() {
                let gw = if gi == 1 { gender } else { 1.0 - gender };
                for (mi, m) in MUSCLE.iter().enumerate() {
                    for (wi, ww) in WEIGHT.iter().enumerate() {
                        let macro_weight = gw * muscle[mi] * weight[wi];
                        w[index(&format!("macrodetails/universal-{g}-young-{m}-{ww}"))] =
                            macro_weight;
                        for (h, hw) in [("minheight", height[0]), ("maxheight", height[2])] {
                            w[index(&format!("macrodetails/height/{g}-young-{m}-{ww}-{h}"))] =
                                macro_weight * hw;
                        }
                        for (p, pw) in [
                            ("uncommonproportions", proportions[0]),
                            ("idealproportions", proportions[2]),
                        ] {
                            w[index(&format!("macrodetails/proportions/{g}-young-{m}-{ww}-{p}"))] =
                                macro_weight * pw;
                        }
                    }
                }
            }
            for (pairs, sd) in [(&MEASURE[..], MEASURE_SD), (&REGIONAL[..], REGIONAL_SD)] {
                for (decr, incr) in pairs {
                    let x =
                        Normal::new(0.0, sd).map_or(0.0, |n| n.sample(&mut rng)).clamp(-1.0, 1.0);
                    w[index(if x < 0.0 { decr } else { incr })] = x.abs();
                }
            }
            let (tag, shapes) =
                if male { ("man", &MALE_SHAPES[..]) } else { ("fem", &FEMALE_SHAPES[..]) };
            let shape = shapes[rng.random_range(0..shapes.len())];
            w[index(&format!("bodyshapes/bodyshapes-elvs-{tag}-{shape}"))] =
                rng.random_range(0.0..SHAPE_WEIGHT);
            w
        })
        .collect();
    Population { targets, bodies }
}

impl Population {
    /// Body `i` as `(target, weight)` pairs with a non-zero weight (for [`crate::pose::makehuman::MakeHuman::shaped`]).
    pub fn recipe(&self, i: usize) -> Vec<(&str, f64)> {
        self.targets
            .iter()
            .zip(&self.bodies[i])
            .filter(|(_, w)| **w != 0.0)
            .map(|(t, w)| (t.as_str(), *w))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn macro_levels_blend_linearly_and_sum_to_one() {
        assert_eq!(levels(0.0), [1.0, 0.0, 0.0]);
        assert_eq!(levels(0.5), [0.0, 1.0, 0.0]);
        assert_eq!(levels(1.0), [0.0, 0.0, 1.0]);
        assert_eq!(levels(0.75), [0.0, 0.5, 0.5]);
        let p = sample(20, 7);
        assert_eq!(p, sample(20, 7), "seeded");
        for body in &p.bodies {
            let universal: f64 = p
                .targets
                .iter()
                .zip(body)
                .filter(|(t, _)| t.contains("universal"))
                .map(|(_, w)| w)
                .sum();
            assert!((universal - 1.0).abs() < 1e-12, "macro weights sum to 1: {universal}");
        }
    }
}
