//! The model's skeleton: the 21 bones a mannequin needs, chosen from MakeHuman's 163, and their
//! skin weights: MakeHuman's, with the weights of dropped bones merged onto their nearest kept
//! ancestor, made exactly mirror-symmetric, stray islands removed, at most
//! [`MAX_INFLUENCES`] bones per vertex, normalised.

use crate::pose::makehuman::Rig;
use crate::pose::skinning::SkinWeights;

/// The kept bones, by MakeHuman name. Each rotates about its MakeHuman head joint; `root` (the
/// pelvis) also carries `spine05` and `pelvis.L/R`, a kept bone carries its twist bone
/// (`upperarm02`, ...), `clavicle` the deltoid (`shoulder01`), `wrist` the fingers, `foot` the
/// toes, `head` the face, `neck01` the upper neck.
pub const BONES: [&str; 21] = [
    "root",
    "spine04",
    "spine03",
    "spine02",
    "spine01",
    "neck01",
    "head",
    "clavicle.L",
    "upperarm01.L",
    "lowerarm01.L",
    "wrist.L",
    "clavicle.R",
    "upperarm01.R",
    "lowerarm01.R",
    "wrist.R",
    "upperleg01.L",
    "lowerleg01.L",
    "foot.L",
    "upperleg01.R",
    "lowerleg01.R",
    "foot.R",
];

/// At most this many bones move a vertex (glTF's one `JOINTS_0`/`WEIGHTS_0` set).
pub const MAX_INFLUENCES: usize = 4;

/// Skin weights are multiples of this (2^-16): exact in `f32` (the file's type) and summing
/// to exactly 1 per vertex.
pub const WEIGHT_QUANTUM: f64 = 1.0 / 65536.0;

/// The bone hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// Bone names (MakeHuman's), parents before children.
    pub names: Vec<String>,
    /// Each bone's parent (a lower index), `None` for the root.
    pub parents: Vec<Option<usize>>,
}

impl Skeleton {
    /// Each bone's mirror partner (`.L` <-> `.R`; itself for the others).
    pub fn mirror(&self) -> Vec<usize> {
        let partner = |n: &str| match (n.strip_suffix(".L"), n.strip_suffix(".R")) {
            (Some(s), _) => format!("{s}.R"),
            (_, Some(s)) => format!("{s}.L"),
            _ => n.to_string(),
        };
        self.names
            .iter()
            .map(|n| self.names.iter().position(|m| *m == partner(n)).unwrap_or(0))
            .collect()
    }
}

/// The reduced skeleton, and for each MakeHuman bone the kept bone it merges into (itself or
/// its nearest kept ancestor). `None` when the rig lacks one of [`BONES`] (named) or its root.
pub fn reduce(rig: &Rig) -> Result<(Skeleton, Vec<usize>), String> {
    let kept: Vec<usize> = BONES
        .iter()
        .map(|n| rig.bone(n).ok_or_else(|| format!("the rig has no bone `{n}`")))
        .collect::<Result<_, _>>()?;
    let mut into: Vec<Option<usize>> = vec![None; rig.bones.len()];
    let mut order: Vec<usize> = Vec::new(); // kept MakeHuman bones in rig (hierarchy) order
    for (b, bone) in rig.bones.iter().enumerate() {
        into[b] = if kept.contains(&b) {
            order.push(b);
            Some(order.len() - 1)
        } else {
            bone.parent.and_then(|p| into[p])
        };
    }
    let parents = order.iter().map(|&b| rig.bones[b].parent.and_then(|p| into[p])).collect();
    let names = order.iter().map(|&b| rig.bones[b].name.clone()).collect();
    let into = into
        .into_iter()
        .enumerate()
        .map(|(b, k)| k.ok_or_else(|| format!("bone `{}` has no kept ancestor", rig.bones[b].name)))
        .collect::<Result<_, _>>()?;
    Ok((Skeleton { names, parents }, into))
}

/// The model's skin weights for the skin vertices, from MakeHuman's (`weights` over the full
/// vertex list, `into` from [`reduce`]). `quads` are the skin's faces in skin-vertex indices
/// (their vertices count as connected), `mirror` the skin's mirror map.
pub fn skin_weights(
    weights: &SkinWeights,
    skin_vertices: &[u32],
    into: &[usize],
    skeleton: &Skeleton,
    quads: &[[u32; 4]],
    mirror: &[u32],
) -> SkinWeights {
    let bones = skeleton.names.len();
    let bone_mirror = skeleton.mirror();
    // Merged onto kept bones: a dense table, vertex by bone.
    let mut w = vec![vec![0.0; bones]; skin_vertices.len()];
    for (k, &v) in skin_vertices.iter().enumerate() {
        for (b, weight) in weights.of(v as usize) {
            w[k][into[b]] += weight;
        }
    }
    let symmetric = |w: &[Vec<f64>]| -> Vec<Vec<f64>> {
        (0..w.len())
            .map(|i| {
                (0..bones)
                    .map(|b| (w[i][b] + w[mirror[i] as usize][bone_mirror[b]]) / 2.0)
                    .collect()
            })
            .collect()
    };
    let mut w = symmetric(&w);
    remove_islands(&mut w, quads, mirror, &bone_mirror);
    let per_vertex = (0..w.len())
        .map(|i| {
            let m = mirror[i] as usize;
            if m < i && m != i {
                // The partner was done first: its weights, mirrored, keep the skin exactly symmetric.
                strongest(&w[m], &bone_mirror, m == i)
                    .into_iter()
                    .map(|(b, x)| (bone_mirror[b], x))
                    .collect()
            } else {
                strongest(&w[i], &bone_mirror, m == i)
            }
        })
        .collect();
    SkinWeights::normalised(per_vertex)
}

/// Drops, for each bone, the weight on vertices not connected (through weighted vertices of
/// that bone) to its main region: the connected piece with the most weight, together with its
/// mirror image for a bone on the symmetry plane (two mirror pieces weigh exactly the same).
fn remove_islands(w: &mut [Vec<f64>], quads: &[[u32; 4]], mirror: &[u32], bone_mirror: &[usize]) {
    let n = w.len();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for q in quads {
        for &a in q {
            neighbours[a as usize].extend(q.iter().filter(|&&b| b != a));
        }
    }
    for bone in 0..bone_mirror.len() {
        let mut piece = vec![usize::MAX; n];
        let mut weight_of: Vec<f64> = Vec::new();
        for start in 0..n {
            if w[start][bone] <= 0.0 || piece[start] != usize::MAX {
                continue;
            }
            let id = weight_of.len();
            let (mut stack, mut total) = (vec![start], 0.0);
            piece[start] = id;
            while let Some(v) = stack.pop() {
                total += w[v][bone];
                for &u in &neighbours[v] {
                    let u = u as usize;
                    if w[u][bone] > 0.0 && piece[u] == usize::MAX {
                        piece[u] = id;
                        stack.push(u);
                    }
                }
            }
            weight_of.push(total);
        }
        let heaviest = weight_of.iter().copied().fold(0.0, f64::max);
        let keep: Vec<bool> = (0..weight_of.len())
            .map(|p| {
                let first = piece.iter().position(|&q| q == p).unwrap_or(0);
                let mirror_piece = piece[mirror[first] as usize];
                let own = weight_of[p];
                let partner = if bone_mirror[bone] == bone && mirror_piece != usize::MAX {
                    weight_of[mirror_piece]
                } else {
                    own
                };
                own.max(partner) >= heaviest
            })
            .collect();
        for v in 0..n {
            if piece[v] != usize::MAX && !keep[piece[v]] {
                w[v][bone] = 0.0;
            }
        }
    }
}

/// A vertex's strongest bones (at most [`MAX_INFLUENCES`]) with weights in multiples of
/// [`WEIGHT_QUANTUM`] summing to exactly 1. On the symmetry plane (`on_plane`) a left/right
/// pair is kept or dropped together and weighted alike, so the vertex stays symmetric.
fn strongest(w: &[f64], bone_mirror: &[usize], on_plane: bool) -> Vec<(usize, f64)> {
    let mut order: Vec<usize> = (0..w.len()).filter(|&b| w[b] > 0.0).collect();
    let pair = |b: usize| b.min(bone_mirror[b]);
    order.sort_by(|&a, &b| w[b].total_cmp(&w[a]).then(pair(a).cmp(&pair(b))).then(a.cmp(&b)));
    let mut chosen: Vec<usize> = Vec::new();
    for &b in &order {
        let partner = bone_mirror[b];
        let together = on_plane && partner != b;
        if chosen.contains(&b) {
            continue;
        }
        let needed = if together { 2 } else { 1 };
        if chosen.len() + needed <= MAX_INFLUENCES {
            chosen.push(b);
            if together {
                chosen.push(partner);
            }
        }
    }
    let total: f64 = chosen.iter().map(|&b| w[b]).sum();
    let steps = (1.0 / WEIGHT_QUANTUM) as i64;
    let mut q: Vec<i64> =
        chosen.iter().map(|&b| (w[b] / total * steps as f64).round() as i64).collect();
    // Put the rounding remainder on the strongest bone that keeps the vertex symmetric: on the
    // plane a central bone, or split over a pair (the total of pairs is even, as is 2^16).
    let rest = steps - q.iter().sum::<i64>();
    let fix = chosen.iter().position(|&b| !on_plane || bone_mirror[b] == b);
    match fix {
        Some(i) => q[i] += rest,
        None => {
            q[0] += rest / 2;
            q[1] += rest / 2;
        }
    }
    chosen
        .into_iter()
        .zip(q)
        .filter(|&(_, x)| x > 0)
        .map(|(b, x)| (b, x as f64 * WEIGHT_QUANTUM))
        .collect()
}
