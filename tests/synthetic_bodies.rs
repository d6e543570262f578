//! The synthetic customers and scans of `capture-sim`, checked with dressform's own topology and
//! slicer (`capture-sim` cannot depend on dressform, so these tests live here):
//! - bodies: one closed, manifold, consistently oriented piece of genus 0 whose tape girths
//!   at the requested levels match the request, for 20 random parameter sets, the asymmetric
//!   pose and the corners of the allowed ranges; the arms are loops of their own;
//! - scans: each hole a scanner leaves is one simple boundary loop at its site.

use capture_sim::{
    Artifacts, BodyParams, GirthLevel, HoleSite, Pose, SyntheticBody, TriangleSurface, capture,
    generate,
};
use dressform::body::mesh::{Mesh, Topology, components, topology};
use dressform::body::slice::{Contour, Section, sections};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::sync::OnceLock;

fn mesh_of(surface: &TriangleSurface) -> Mesh {
    Mesh::new(
        surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
        surface.triangles.clone(),
    )
}

/// What the edges, pieces and vertices of a surface say about it.
#[derive(Debug)]
struct Census {
    topology: Topology,
    /// Connected pieces.
    components: usize,
    /// Vertices no triangle uses.
    unused_vertices: usize,
    /// V - E + F over the used vertices: 2 for a sphere, 2 - h with h holes.
    euler: i64,
}

fn census(mesh: &Mesh) -> Census {
    let topology = topology(mesh);
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.triangles.iter().flatten() {
        used[v as usize] = true;
    }
    let used = used.iter().filter(|&&u| u).count();
    let euler = used as i64 - topology.edges as i64 + mesh.triangles.len() as i64;
    Census {
        components: components(mesh).count,
        unused_vertices: mesh.positions.len() - used,
        euler,
        topology,
    }
}

/// One closed, manifold, consistently oriented piece with no stray vertices (every edge
/// shared by exactly two triangles running opposite ways).
fn assert_one_clean_piece(c: &Census, what: &str) {
    let t = &c.topology;
    assert_eq!(t.non_manifold_edges, 0, "{what}: {c:?}");
    assert_eq!(t.misoriented_edges, 0, "{what}: {c:?}");
    assert_eq!(t.non_manifold_vertices, 0, "{what}: {c:?}");
    assert_eq!(c.components, 1, "{what}: {c:?}");
    assert_eq!(c.unused_vertices, 0, "{what}: {c:?}");
}

/// The loop of `section` around `centre`.
fn loop_around(section: &Section, centre: [f64; 2]) -> Option<&Contour> {
    section.loops.iter().find(|l| l.contains(DVec2::from_array(centre)))
}

/// The body's torso tape girths at its chest, waist and hip levels, relative to `requested`
/// (minus 1), each from the loop around the level's centre.
fn girth_errors(body: &SyntheticBody, requested: [f64; 3], what: &str) -> [f64; 3] {
    let mesh = mesh_of(&body.surface);
    let truth = &body.truth;
    let levels = [truth.chest, truth.waist, truth.hip];
    let heights: Vec<f64> = levels.iter().map(|l| l.z_mm).collect();
    let cut = sections(&mesh, &heights);
    let mut errors = [0.0; 3];
    for (i, (level, section)) in levels.iter().zip(&cut).enumerate() {
        let torso = loop_around(section, level.centre_xy_mm)
            .unwrap_or_else(|| panic!("{what}: no torso loop at z = {}", level.z_mm));
        errors[i] = torso.tape_girth() / requested[i] - 1.0;
    }
    errors
}

/// Checks one body; returns its girth errors against the request (chest, waist, hip).
fn check(params: &BodyParams, what: &str) -> [f64; 3] {
    let body = generate(params).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mesh = mesh_of(&body.surface);
    let c = census(&mesh);
    assert_one_clean_piece(&c, what);
    assert!(c.topology.is_closed(), "{what}: {} holes", c.topology.boundary_loops.len());
    assert_eq!(c.euler, 2, "{what}: genus 0, a sphere: {c:?}");
    // Outward orientation: positive enclosed volume, of a plausible size (litres).
    let litres = mesh.signed_volume() / 1e6;
    assert!((30.0..250.0).contains(&litres), "{what}: {litres} l");

    // Stature and crotch: the mesh reaches the head top and the floor; truth matches request.
    let bounds = mesh.bounds().expect("vertices");
    let height = bounds.size().z;
    let truth = &body.truth;
    assert!((height - truth.height_mm).abs() < 0.01 * truth.height_mm, "{what}: height {height}");
    assert!(bounds.min.z.abs() < 0.5, "{what}: floor at {}", bounds.min.z);
    assert!((bounds.max.z - params.height_mm).abs() < 1.0, "{what}: top at {}", bounds.max.z);
    assert!((truth.crotch_height_mm - params.leg_length_mm).abs() < 0.1, "{what}");
    assert!((truth.height_mm - params.height_mm).abs() < 0.1, "{what}");

    // The girths: against the request, and against the truth the generator reports.
    let requested = [params.chest_girth_mm, params.waist_girth_mm, params.hip_girth_mm];
    let errors = girth_errors(&body, requested, what);
    let told = [truth.chest, truth.waist, truth.hip].map(|l: GirthLevel| l.tape_girth_mm);
    let against_truth = girth_errors(&body, told, what);
    for ((e, t), name) in errors.iter().zip(against_truth).zip(["chest", "waist", "hip"]) {
        assert!(e.abs() < 0.003, "{what}: {name} girth off the request by {:.3}%", e * 100.0);
        assert!(t.abs() < 0.01, "{what}: {name} girth off the truth by {:.3}%", t * 100.0);
    }
    errors
}

#[test]
fn twenty_random_bodies_are_one_closed_piece_with_the_requested_girths() {
    let errors: Vec<[f64; 3]> = (0..20u64)
        .into_par_iter()
        .map(|seed| check(&BodyParams::random(seed), &format!("seed {seed}")))
        .collect();
    let max = |l: usize| errors.iter().map(|e| e[l].abs()).fold(0.0, f64::max);
    println!(
        "max |girth error| over 20 bodies: chest {:.4}%, waist {:.4}%, hip {:.4}%",
        100.0 * max(0),
        100.0 * max(1),
        100.0 * max(2)
    );
}

#[test]
fn the_asymmetric_pose_keeps_girths_and_surface() {
    let params = BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() };
    check(&params, "asymmetric pose");
}

/// Bodies at extremes of the allowed ranges (coarse grid for speed) generate closed and
/// manifold with their girths.
#[test]
fn corner_bodies_generate() {
    let base = BodyParams { resolution_mm: 8.0, ..BodyParams::default() };
    let corners = [
        // Short, heavy, round belly, wide hips.
        (1400.0, 1150.0, 1300.0, 1600.0, 0.18, 0.42, 1.0),
        // Tall and slim.
        (2100.0, 800.0, 560.0, 800.0, 0.28, 0.50, 0.0),
        // Tall and heavy.
        (2100.0, 1600.0, 1600.0, 1700.0, 0.26, 0.44, 0.3),
        // Short and slim, long legs.
        (1400.0, 650.0, 500.0, 750.0, 0.22, 0.50, 0.6),
    ];
    corners.par_iter().for_each(|&(h, c, w, hip, s, l, bust)| {
        let p = BodyParams {
            height_mm: h,
            chest_girth_mm: c,
            waist_girth_mm: w,
            hip_girth_mm: hip,
            shoulder_width_mm: s * h,
            leg_length_mm: l * h,
            bust_prominence: bust,
            ..base.clone()
        };
        // Open the arms until they clear the torso (the girths below are of the mesh's
        // loop around the centre, which would hold an arm resting on the torso).
        let p = p.with_arms_clear();
        let what = format!("{p:?}");
        let body = generate(&p).unwrap_or_else(|e| panic!("{what}: {e}"));
        let census = census(&mesh_of(&body.surface));
        assert_one_clean_piece(&census, &what);
        assert!(census.topology.is_closed(), "{what}: {census:?}");
        for e in girth_errors(&body, [c, w, hip], &what) {
            assert!(e.abs() < 0.005, "{what}: girth off by {:.3}%", 100.0 * e);
        }
    });
}

#[test]
fn arms_are_separate_loops_at_the_girth_levels() {
    let body = generate(&BodyParams::default()).expect("default body");
    let mesh = mesh_of(&body.surface);
    let truth = &body.truth;
    let levels = [&truth.chest, &truth.waist, &truth.hip];
    let cut = sections(&mesh, &levels.map(|l| l.z_mm));
    for (level, section) in levels.iter().zip(&cut) {
        let centre = DVec2::from_array(level.centre_xy_mm);
        let torso: Vec<&Contour> = section.loops.iter().filter(|l| l.contains(centre)).collect();
        assert_eq!(torso.len(), 1, "z = {}", level.z_mm);
        // The torso loop stays within the torso: no point beyond the shoulders' width.
        let half_width = torso[0].points.iter().map(|p| p.x.abs()).fold(0.0, f64::max);
        assert!(half_width < 0.5 * body.params.shoulder_width_mm, "z = {}", level.z_mm);
    }
    // Chest and waist sections cut both arms (hands hang below the hip in the A-pose).
    assert!(cut[0].loops.len() >= 3, "chest: {} loops", cut[0].loops.len());
    assert!(cut[1].loops.len() >= 3, "waist: {} loops", cut[1].loops.len());
}

/// One default body shared by the scan tests (generated once).
fn body() -> &'static SyntheticBody {
    static BODY: OnceLock<SyntheticBody> = OnceLock::new();
    BODY.get_or_init(|| generate(&BodyParams::default()).expect("default body"))
}

#[test]
fn holes_leave_one_simple_loop_per_site() {
    let b = body();
    for (sites, loops) in [
        (vec![HoleSite::Armpits], 2),
        (vec![HoleSite::Crotch], 1),
        (vec![HoleSite::Soles], 2),
        (vec![HoleSite::Armpits, HoleSite::Crotch, HoleSite::Soles], 5),
    ] {
        let artifacts = Artifacts { holes: sites.clone(), ..Artifacts::default() };
        let s = capture(b, &artifacts);
        let c = census(&mesh_of(&s));
        let what = format!("{sites:?}");
        assert_eq!(c.topology.boundary_loops.len(), loops, "{what}: {c:?}");
        assert_one_clean_piece(&c, &what);
        // Each hole is a disk removed from a sphere: Euler characteristic 2 - loops.
        assert_eq!(c.euler, 2 - loops as i64, "{what}: {c:?}");
        // Small holes: most of the surface stays.
        assert!(s.triangles.len() as f64 > 0.97 * b.surface.triangles.len() as f64);
    }
}

#[test]
fn a_typical_scanner_leaves_five_holes_in_metres_y_up() {
    let b = body();
    let s = capture(b, &Artifacts::typical_scanner(3));
    let c = census(&mesh_of(&s));
    assert_eq!(c.topology.boundary_loops.len(), 5, "{c:?}");
    let (lo, hi) = s.bounds().expect("vertices");
    // Metres, Y up.
    assert!((hi[1] - lo[1] - 1.7).abs() < 0.01, "{lo:?} {hi:?}");
}
