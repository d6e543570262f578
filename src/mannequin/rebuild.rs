//! Rebuilding a watertight mesh from the symmetric rings.
//!
//! - Neighbouring rings are stitched into a band of triangles ([`stitch`]); rings of equal
//!   size give a strip of quads.
//! - Each torso ring also gets a vertex on the symmetry plane at the front and at the back
//!   (the midpoint of the edge that crosses it: no change of shape), where the crotch seam
//!   starts and ends.
//! - The crotch: the lowest torso ring is split at the plane into its left and right halves; a
//!   seam runs along the plane from front to back, between the legs. The left leg's top ring is
//!   stitched to "left half + seam", the right leg's to "seam + right half"; the seam's edges
//!   are shared by the two, so the surface stays closed and manifold.
//! - Caps (a fan around the ring's centre) close the neck and the two ankles.

use super::Layer;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};

/// Adds the points of a ring at height `z`; returns their vertex indices.
fn add_ring(mesh: &mut Mesh, points: &[DVec2], z: f64) -> Vec<u32> {
    let first = mesh.positions.len() as u32;
    mesh.positions.extend(points.iter().map(|p| p.extend(z)));
    (first..mesh.positions.len() as u32).collect()
}

/// Stitches closed ring `lower` to closed ring `upper` (both counter-clockwise from above,
/// starting near the front), choosing at each step the shorter diagonal. Makes
/// `lower.len() + upper.len()` outward-facing triangles.
fn stitch(mesh: &mut Mesh, lower: &[u32], upper: &[u32]) {
    let (na, nb) = (lower.len(), upper.len());
    let p = |i: u32| mesh.positions[i as usize];
    let (mut i, mut j) = (0, 0);
    let mut triangles = Vec::with_capacity(na + nb);
    while i < na || j < nb {
        let (a, a_next) = (lower[i % na], lower[(i + 1) % na]);
        let (b, b_next) = (upper[j % nb], upper[(j + 1) % nb]);
        let advance_lower =
            j == nb || (i < na && p(a_next).distance(p(b)) < p(a).distance(p(b_next)));
        if advance_lower {
            triangles.push([a, a_next, b]);
            i += 1;
        } else {
            triangles.push([a, b_next, b]);
            j += 1;
        }
    }
    mesh.triangles.extend(triangles);
}

/// Closes ring `ring` with a fan around a new vertex at `centre`; `up` for a top cap.
fn cap(mesh: &mut Mesh, ring: &[u32], centre: DVec3, up: bool) {
    let c = mesh.positions.len() as u32;
    mesh.positions.push(centre);
    let n = ring.len();
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        mesh.triangles.push(if up { [a, b, c] } else { [b, a, c] });
    }
}

/// A torso ring with its front and back vertices on the symmetry plane inserted: the front
/// one first, then the left half (front to back), the back one, the right half (back to front).
fn with_midline(points: &[DVec2]) -> (Vec<DVec2>, usize) {
    let n = points.len(); // rays - 2
    let half = n / 2; // points per side
    let front = (points[n - 1] + points[0]) * 0.5;
    let back = (points[half - 1] + points[half]) * 0.5;
    let mut out = Vec::with_capacity(n + 2);
    out.push(front);
    out.extend_from_slice(&points[..half]);
    out.push(back);
    out.extend_from_slice(&points[half..]);
    (out, half + 1)
}

/// The mannequin mesh from its layers (each list bottom to top) and symmetry plane.
pub(super) fn rebuild(torso: &[Layer], left: &[Layer], right: &[Layer], axis: f64) -> Mesh {
    let mut mesh = Mesh::default();

    let mut torso_rings = Vec::with_capacity(torso.len());
    let mut back_index = 0;
    for layer in torso {
        let (points, back) = with_midline(&layer.points);
        back_index = back;
        torso_rings.push(add_ring(&mut mesh, &points, layer.z));
    }
    for pair in torso_rings.windows(2) {
        stitch(&mut mesh, &pair[0], &pair[1]);
    }
    let top = torso.last().expect("at least two torso layers");
    cap(
        &mut mesh,
        torso_rings.last().expect("rings"),
        DVec3::new(axis, top.centre[1], top.z),
        true,
    );

    let mut leg_tops = Vec::with_capacity(2);
    for leg in [left, right] {
        let rings: Vec<Vec<u32>> =
            leg.iter().map(|l| add_ring(&mut mesh, &l.points, l.z)).collect();
        for pair in rings.windows(2) {
            stitch(&mut mesh, &pair[0], &pair[1]);
        }
        let bottom = &leg[0];
        cap(&mut mesh, &rings[0], DVec3::new(bottom.centre[0], bottom.centre[1], bottom.z), false);
        leg_tops.push(rings.last().expect("at least two leg layers").clone());
    }

    // The crotch seam, on the symmetry plane, halfway between the torso and the leg tops.
    let ring0 = &torso_rings[0];
    let (front, back) =
        (mesh.positions[ring0[0] as usize], mesh.positions[ring0[back_index] as usize]);
    let seam_z = 0.5 * (torso[0].z + left.last().expect("legs").z);
    let seam_points = (ring0.len() / 8).max(1);
    let seam: Vec<u32> = (1..=seam_points)
        .map(|k| {
            let t = k as f64 / (seam_points + 1) as f64;
            let p = front.lerp(back, t);
            mesh.positions.push(DVec3::new(axis, p.y, seam_z));
            (mesh.positions.len() - 1) as u32
        })
        .collect();
    let mut left_boundary: Vec<u32> = ring0[..=back_index].to_vec();
    left_boundary.extend(seam.iter().rev());
    let mut right_boundary: Vec<u32> = vec![ring0[0]];
    right_boundary.extend(&seam);
    right_boundary.extend(&ring0[back_index..]);
    stitch(&mut mesh, &leg_tops[0], &left_boundary);
    stitch(&mut mesh, &leg_tops[1], &right_boundary);
    mesh
}
