//! Scanner artifacts: what a real scanner hands over instead of the clean body — noise along
//! the normals, holes where it cannot see (armpits, crotch, soles), its own units and up axis,
//! and an arbitrary turn of the subject about the vertical.

use glam::DVec3;
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rustc_hash::FxHashMap;

use super::SyntheticBody;
use super::surface::TriangleSurface;

/// Where a scanner leaves a hole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HoleSite {
    /// One hole in each armpit.
    Armpits,
    /// One hole at the crotch.
    Crotch,
    /// One hole in each sole.
    Soles,
}

/// Length unit of the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Units {
    /// Metres.
    M,
    /// Decimetres (MakeHuman).
    Dm,
    /// Centimetres.
    Cm,
    /// Millimetres (the canonical frame's unit).
    Mm,
}

impl Units {
    /// Millimetres in one unit.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::M => 1000.0,
            Units::Dm => 100.0,
            Units::Cm => 10.0,
            Units::Mm => 1.0,
        }
    }
}

/// Up axis of the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UpAxis {
    /// Y up: canonical (x, y, z) becomes (x, z, -y), the subject faces +Z (MakeHuman, glTF).
    Y,
    /// Z up, the canonical frame (the subject faces -Y).
    Z,
}

/// The artifacts to apply. The default is a perfect scanner: no noise, no holes,
/// millimetres, Z up, no turn.
#[derive(Debug, Clone, PartialEq)]
pub struct Artifacts {
    /// Standard deviation of the Gaussian displacement of each vertex along its normal (mm).
    /// Zero, negative or non-finite values mean no noise.
    pub noise_sigma_mm: f64,
    /// Where to cut holes.
    pub holes: Vec<HoleSite>,
    /// Radius of each hole (mm): triangles whose centroid lies within it of the site go.
    /// Zero, negative or non-finite values mean no holes.
    pub hole_radius_mm: f64,
    /// Length unit of the output.
    pub units: Units,
    /// Up axis of the output.
    pub up: UpAxis,
    /// Turn of the subject about the vertical, counter-clockwise seen from above (degrees);
    /// non-finite values mean no turn.
    pub yaw_deg: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for Artifacts {
    fn default() -> Self {
        Artifacts {
            noise_sigma_mm: 0.0,
            holes: Vec::new(),
            hole_radius_mm: 20.0,
            units: Units::Mm,
            up: UpAxis::Z,
            yaw_deg: 0.0,
            seed: 0,
        }
    }
}

impl Artifacts {
    /// A typical consumer scan: 1 mm noise, 20 mm holes at the armpits, crotch and soles,
    /// metres, Y up, the subject turned by 15 degrees.
    pub fn typical_scanner(seed: u64) -> Self {
        Artifacts {
            noise_sigma_mm: 1.0,
            holes: vec![HoleSite::Armpits, HoleSite::Crotch, HoleSite::Soles],
            hole_radius_mm: 20.0,
            units: Units::M,
            up: UpAxis::Y,
            yaw_deg: 15.0,
            seed,
        }
    }
}

/// What a scanner would hand over for `body`: its surface with `artifacts` applied, in this
/// order: noise (canonical frame), holes, yaw about the vertical, up axis, units. Without
/// holes the vertices keep their order and count; with holes the unused vertices are dropped
/// (the others keep their relative order). Deterministic for a given seed.
pub fn capture(body: &SyntheticBody, artifacts: &Artifacts) -> TriangleSurface {
    let mut sites = Vec::new();
    for site in &artifacts.holes {
        let lm = &body.truth.landmarks;
        match site {
            HoleSite::Armpits => sites.extend([lm.left.armpit, lm.right.armpit]),
            HoleSite::Crotch => sites.push(lm.crotch),
            HoleSite::Soles => sites.extend([lm.left.sole_centre, lm.right.sole_centre]),
        }
    }
    let mut surface = with_noise_and_holes(
        &body.surface,
        artifacts.noise_sigma_mm,
        &sites,
        artifacts.hole_radius_mm,
        artifacts.seed,
    );
    let (sin, cos) = artifacts.yaw_deg.to_radians().sin_cos();
    let turn = artifacts.yaw_deg.is_finite() && artifacts.yaw_deg != 0.0;
    let scale = artifacts.units.mm_per_unit();
    for p in &mut surface.positions {
        let [mut x, mut y, z] = *p;
        if turn {
            (x, y) = (x * cos - y * sin, x * sin + y * cos);
        }
        let q = match artifacts.up {
            UpAxis::Z => [x, y, z],
            UpAxis::Y => [x, z, -y],
        };
        *p = q.map(|v| v / scale);
    }
    surface
}

/// A scanner's noise and holes on any surface (mm): each vertex moved along its normal by a
/// Gaussian amount of deviation `noise_sigma_mm` (from `seed`), then the triangles within
/// `hole_radius_mm` of any of `sites` removed (as [`capture`] does at the armpits, crotch and
/// soles); a zero, negative or non-finite deviation or radius means none.
pub fn with_noise_and_holes(
    surface: &TriangleSurface,
    noise_sigma_mm: f64,
    sites: &[[f64; 3]],
    hole_radius_mm: f64,
    seed: u64,
) -> TriangleSurface {
    let mut surface = surface.clone();
    add_noise(&mut surface, noise_sigma_mm, seed);
    if !sites.is_empty() && hole_radius_mm.is_finite() && hole_radius_mm > 0.0 {
        surface = cut_holes(&surface, sites, hole_radius_mm);
    }
    surface
}

/// Moves each vertex along its normal by a Gaussian amount of deviation `sigma` (mm).
fn add_noise(surface: &mut TriangleSurface, sigma: f64, seed: u64) {
    let Ok(normal) = Normal::new(0.0, sigma) else {
        return;
    };
    if sigma <= 0.0 {
        return;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normals = surface.vertex_normals();
    for (p, n) in surface.positions.iter_mut().zip(normals) {
        let d: f64 = normal.sample(&mut rng);
        for (x, nx) in p.iter_mut().zip(n) {
            *x += d * nx;
        }
    }
}

/// Removes the triangles whose centroid lies within `radius` of any of `sites`, then, so that
/// every hole is bounded by simple loops, also the triangles around any vertex where the
/// remaining surface would be pinched (more than two boundary edges). Drops unused vertices.
fn cut_holes(surface: &TriangleSurface, sites: &[[f64; 3]], radius: f64) -> TriangleSurface {
    let pos = |i: u32| DVec3::from_array(surface.positions[i as usize]);
    let mut keep: Vec<bool> = surface
        .triangles
        .iter()
        .map(|t| {
            let c = (pos(t[0]) + pos(t[1]) + pos(t[2])) / 3.0;
            sites.iter().all(|s| c.distance(DVec3::from_array(*s)) > radius)
        })
        .collect();
    // Remove pinches until every boundary vertex has exactly two boundary edges.
    for _ in 0..100 {
        let mut edge_count: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for (t, _) in surface.triangles.iter().zip(&keep).filter(|(_, k)| **k) {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *edge_count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut boundary_degree: FxHashMap<u32, u32> = FxHashMap::default();
        for (&(a, b), &n) in &edge_count {
            if n == 1 {
                *boundary_degree.entry(a).or_insert(0) += 1;
                *boundary_degree.entry(b).or_insert(0) += 1;
            }
        }
        let pinched: Vec<u32> =
            boundary_degree.iter().filter(|&(_, &d)| d > 2).map(|(&v, _)| v).collect();
        if pinched.is_empty() {
            break;
        }
        for (t, k) in surface.triangles.iter().zip(keep.iter_mut()) {
            if t.iter().any(|v| pinched.contains(v)) {
                *k = false;
            }
        }
    }
    let mut new_index = vec![u32::MAX; surface.positions.len()];
    let mut out = TriangleSurface::default();
    let kept: Vec<[u32; 3]> =
        surface.triangles.iter().zip(&keep).filter(|(_, k)| **k).map(|(t, _)| *t).collect();
    let mut used = vec![false; surface.positions.len()];
    for t in &kept {
        for &v in t {
            used[v as usize] = true;
        }
    }
    for (i, p) in surface.positions.iter().enumerate() {
        if used[i] {
            new_index[i] = out.positions.len() as u32;
            out.positions.push(*p);
        }
    }
    out.triangles = kept.iter().map(|t| t.map(|v| new_index[v as usize])).collect();
    out
}
