//! The synthetic customers of `sim`, measured with dressform's own slicer: the tape girths at
//! the requested levels match the request within 1%, and the surface is one closed, manifold,
//! consistently oriented piece — for 20 random parameter sets and the asymmetric pose.

use dressform::mesh::{Mesh, components, topology};
use dressform::slice::sections;
use glam::{DVec2, DVec3};
use sim::capture::{BodyParams, Pose, SyntheticBody, generate};

fn mesh_of(body: &SyntheticBody) -> Mesh {
    Mesh::new(
        body.surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
        body.surface.triangles.clone(),
    )
}

/// Checks one body; returns the worst relative girth error.
fn check(params: &BodyParams, what: &str) -> f64 {
    let body = generate(params).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mesh = mesh_of(&body);
    let t = topology(&mesh);
    assert!(t.is_closed(), "{what}: {} holes", t.boundary_loops.len());
    assert!(t.is_manifold(), "{what}: {t:?}");
    assert!(t.is_consistently_oriented(), "{what}: {} flipped edges", t.misoriented_edges);
    assert_eq!(components(&mesh).parts.len(), 1, "{what}: one piece");
    assert!(mesh.signed_volume() > 0.0, "{what}: normals point outward");
    let height = mesh.bounds().unwrap().size().z;
    assert!(
        (height - body.truth.height_mm).abs() < 0.01 * body.truth.height_mm,
        "{what}: height {height}"
    );

    let truth = &body.truth;
    let levels = [("chest", truth.chest), ("waist", truth.waist), ("hip", truth.hip)];
    let heights: Vec<f64> = levels.iter().map(|(_, l)| l.z_mm).collect();
    let mut worst: f64 = 0.0;
    for ((name, level), section) in levels.iter().zip(sections(&mesh, &heights)) {
        // The torso is the loop around the body's centre line.
        let torso = section
            .loops
            .iter()
            .find(|l| l.contains(DVec2::ZERO))
            .unwrap_or_else(|| panic!("{what}: no loop around the centre at the {name}"));
        let error = (torso.tape_girth() - level.tape_girth_mm) / level.tape_girth_mm;
        assert!(
            error.abs() < 0.01,
            "{what}: {name} tape girth {:.1} mm at z = {:.0}, asked {:.1} mm ({:+.2}%)",
            torso.tape_girth(),
            level.z_mm,
            level.tape_girth_mm,
            100.0 * error
        );
        worst = worst.max(error.abs());
    }
    worst
}

#[test]
fn twenty_random_bodies_have_the_requested_girths_and_a_closed_manifold_surface() {
    let mut worst: f64 = 0.0;
    for seed in 0..20 {
        worst = worst.max(check(&BodyParams::random(seed), &format!("seed {seed}")));
    }
    eprintln!("largest girth error over 20 bodies: {:.3}%", 100.0 * worst);
}

#[test]
fn the_asymmetric_pose_keeps_girths_and_surface() {
    let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
    check(&params, "asymmetric pose");
}
