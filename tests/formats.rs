//! Round trips through every mesh format we read and write, reading the variants we only read
//! (ASCII and big-endian PLY, ASCII STL), and exports for CAD in every unit and up axis.

use dressform::body::mesh::Mesh;
use dressform::body::scan::format::{Export, Format, Placement, UpAxis, comment_value};
use dressform::body::scan::frame::Units;
use glam::DVec3;
use std::fmt::Write as _;

/// An irregular closed mesh (an octahedron with awkward coordinates).
fn sample() -> Mesh {
    let p = [
        [0.1, -0.333_333_333_333_3, 1e-7],
        [1234.5678, 0.0, 3.0],
        [-7.25, 9.875, -0.001],
        [2.0 / 3.0, 1e5, 17.0],
        [-1.0, -1.0, 1.0 / 7.0],
        [3.3, 4.4, 5.5],
    ];
    let t = vec![
        [0, 1, 2],
        [0, 2, 3],
        [0, 3, 4],
        [0, 4, 1],
        [5, 2, 1],
        [5, 3, 2],
        [5, 4, 3],
        [5, 1, 4],
    ];
    Mesh::new(p.iter().map(|&a| DVec3::from_array(a)).collect(), t)
}

/// Corner positions of every triangle, in order: independent of vertex numbering.
fn corners(mesh: &Mesh) -> Vec<[DVec3; 3]> {
    (0..mesh.triangles.len()).map(|t| mesh.corners(t)).collect()
}

#[test]
fn obj_round_trip_is_exact() {
    let mesh = sample();
    let back = Format::Obj.read(&Format::Obj.encode(&mesh)).unwrap();
    assert_eq!(back, mesh);
}

#[test]
fn binary_ply_round_trip_is_exact() {
    let mesh = sample();
    let back = Format::Ply.read(&Format::Ply.encode(&mesh)).unwrap();
    assert_eq!(back, mesh);
}

#[test]
fn binary_stl_round_trip_is_exact_in_f32() {
    let mesh = sample().map_positions(|p| p.as_vec3().as_dvec3());
    let back = Format::Stl.read(&Format::Stl.encode(&mesh)).unwrap();
    assert_eq!(corners(&back), corners(&mesh));
    assert_eq!(back.positions.len(), mesh.positions.len(), "STL corners are welded");
}

#[test]
fn binary_stl_whose_header_starts_with_solid_is_read_as_binary() {
    let mesh = sample().map_positions(|p| p.as_vec3().as_dvec3());
    let mut bytes = Format::Stl.encode(&mesh);
    bytes[..12].copy_from_slice(b"solid scan42");
    assert_eq!(corners(&Format::Stl.read(&bytes).unwrap()), corners(&mesh));
}

fn ascii_ply(mesh: &Mesh, quads: bool) -> Vec<u8> {
    let mut s = String::new();
    let faces = if quads { 1 } else { mesh.triangles.len() };
    let _ = write!(
        s,
        "ply\nformat ascii 1.0\ncomment test\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nelement face {faces}\nproperty list uchar int vertex_indices\n\
         end_header\n",
        mesh.positions.len()
    );
    for p in &mesh.positions {
        let _ = writeln!(s, "{:e} {:e} {:e} 255", p.x as f32, p.y as f32, p.z as f32);
    }
    if quads {
        s.push_str("4 0 1 2 3\n");
    } else {
        for t in &mesh.triangles {
            let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
        }
    }
    s.into_bytes()
}

#[test]
fn ascii_ply_reads_to_printed_precision() {
    let mesh = sample();
    let back = Format::Ply.read(&ascii_ply(&mesh, false)).unwrap();
    assert_eq!(back.triangles, mesh.triangles);
    for (a, b) in back.positions.iter().zip(&mesh.positions) {
        assert!((*a - *b).length() <= 1e-6 * b.length().max(1.0), "{a} vs {b}");
    }
}

#[test]
fn ply_polygons_are_triangulated() {
    let back = Format::Ply.read(&ascii_ply(&sample(), true)).unwrap();
    assert_eq!(back.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn big_endian_ply_reads_exactly() {
    let mesh = sample();
    let mut bytes = format!(
        "ply\nformat binary_big_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    for p in &mesh.positions {
        for c in p.to_array() {
            bytes.extend(c.to_be_bytes());
        }
    }
    for t in &mesh.triangles {
        bytes.push(3);
        for i in t {
            bytes.extend(i.to_be_bytes());
        }
    }
    assert_eq!(Format::Ply.read(&bytes).unwrap(), mesh);
}

#[test]
fn ascii_stl_reads_to_printed_precision() {
    let mesh = sample();
    let mut s = String::from("solid test\n");
    for t in 0..mesh.triangles.len() {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for p in mesh.corners(t) {
            let _ = writeln!(s, "vertex {:e} {:e} {:e}", p.x as f32, p.y as f32, p.z as f32);
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid test\n");
    let back = Format::Stl.read(s.as_bytes()).unwrap();
    for (a, b) in corners(&back).iter().zip(corners(&mesh)) {
        for k in 0..3 {
            assert!((a[k] - b[k]).length() <= 1e-6 * b[k].length().max(1.0));
        }
    }
}

#[test]
fn obj_quads_and_groups_are_read_and_triangulated() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\ng a\nf 1 2 3 4\ng b\nf 1 2 5\n";
    let mesh = Format::Obj.read(text.as_bytes()).unwrap();
    assert_eq!(mesh.triangles.len(), 3);
}

/// A little-endian binary PLY as scanners write it: `float` coordinates with a colour byte,
/// and faces with a flag byte before a `uchar int` index list. Each face is a list of indices.
fn scanner_ply(positions: &[DVec3], faces: &[Vec<i32>]) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nelement face {}\nproperty uchar flags\n\
         property list uchar int vertex_indices\nend_header\n",
        positions.len(),
        faces.len()
    )
    .into_bytes();
    for p in positions {
        for c in p.to_array() {
            bytes.extend((c as f32).to_le_bytes());
        }
        bytes.push(200);
    }
    for f in faces {
        bytes.push(7);
        bytes.push(f.len() as u8);
        for i in f {
            bytes.extend(i.to_le_bytes());
        }
    }
    bytes
}

#[test]
fn binary_ply_with_extra_properties_reads_triangles_and_polygons() {
    let mesh = sample().map_positions(|p| p.as_vec3().as_dvec3());
    let faces: Vec<Vec<i32>> =
        mesh.triangles.iter().map(|t| t.iter().map(|&i| i as i32).collect()).collect();
    assert_eq!(Format::Ply.read(&scanner_ply(&mesh.positions, &faces)).unwrap(), mesh);

    // One quad among the triangles: faces no longer have one size.
    let mut mixed = faces.clone();
    mixed[1] = vec![0, 2, 3, 4];
    let back = Format::Ply.read(&scanner_ply(&mesh.positions, &mixed)).unwrap();
    assert_eq!(back.triangles.len(), mesh.triangles.len() + 1);
    assert_eq!(&back.triangles[1..3], &[[0, 2, 3], [0, 3, 4]]);
}

#[test]
fn binary_ply_face_index_out_of_range_names_the_face_and_the_index() {
    let mesh = sample();
    let mut faces: Vec<Vec<i32>> =
        mesh.triangles.iter().map(|t| t.iter().map(|&i| i as i32).collect()).collect();
    for (bad, expected) in [(99, "face 5 refers to vertex 99"), (-1, "face 5 refers to vertex -1")]
    {
        faces[5][2] = bad;
        let err = Format::Ply.read(&scanner_ply(&mesh.positions, &faces)).unwrap_err();
        assert!(err.to_string().contains(expected), "{err}");
        // The same with faces of mixed sizes (read one by one).
        let mut mixed = faces.clone();
        mixed[0].push(4);
        let err = Format::Ply.read(&scanner_ply(&mesh.positions, &mixed)).unwrap_err();
        assert!(err.to_string().contains(expected), "{err}");
    }
}

// Exports (issue 12, "Exports for CAD"): every format, unit and up axis reads back to the
// canonical mesh within the 0.001 mm grid, with units and axes named in the header.

/// A body-sized mesh in the canonical frame (mm, Z up).
fn canonical_body() -> Mesh {
    sample().map_positions(|p| DVec3::new(p.x * 0.3, p.y * 0.002 - 100.0, p.z * 90.0 + 20.0))
}

/// A file point back in the canonical frame.
fn to_canonical(p: DVec3, units: Units, up: UpAxis) -> DVec3 {
    let p = p * units.mm();
    match up {
        UpAxis::Z => p,
        UpAxis::Y => DVec3::new(p.x, -p.z, p.y),
    }
}

#[test]
fn exports_read_back_in_every_format_unit_and_axis() {
    let mesh = canonical_body();
    for format in Format::ALL {
        for units in [Units::Mm, Units::Cm, Units::M] {
            for up in [UpAxis::Z, UpAxis::Y] {
                let Ok(export) = Export::new(format, Placement::Canonical { units, up }) else {
                    assert_eq!(format, Format::Glb);
                    continue;
                };
                let export = export.with_comments(["crotch: 812.5".to_string()]);
                let file = format.decode(&export.encode(&mesh)).unwrap();
                // STL and glb store f32: a few ten-thousandths of a mm at body size.
                let tolerance =
                    if matches!(format, Format::Stl | Format::Glb) { 1e-3 } else { 5e-4 };
                for (a, b) in corners(&file.mesh).iter().zip(corners(&mesh)) {
                    for k in 0..3 {
                        let back = to_canonical(a[k], units, up);
                        let off = (back - b[k]).abs().max_element();
                        assert!(
                            off <= tolerance + 1e-9,
                            "{format} {units} {up:?}: {back} vs {}",
                            b[k]
                        );
                    }
                }
                if format != Format::Stl {
                    let c = &file.comments;
                    assert_eq!(comment_value(c, "units"), Some(units.to_string().as_str()));
                    let named = if up == UpAxis::Z { "+z" } else { "+y" };
                    assert_eq!(comment_value(c, "up"), Some(named), "{format}");
                    assert_eq!(comment_value(c, "crotch"), Some("812.5"), "{format}");
                }
            }
        }
    }
}

#[test]
fn obj_numbers_are_the_shortest_at_a_thousandth_of_a_millimetre() {
    let mesh = canonical_body().map_positions(|p| p + DVec3::splat(1.0 / 3.0));
    let text = String::from_utf8(Export::canonical(Format::Obj).encode(&mesh)).unwrap();
    for line in text.lines().filter(|l| l.starts_with("v ")) {
        for number in line.split(' ').skip(1) {
            let decimals = number.split_once('.').map_or(0, |(_, d)| d.len());
            assert!(decimals <= 3, "{number} in {line}");
            assert!(number.parse::<f64>().unwrap().is_finite());
        }
    }
    assert!(text.starts_with("# written by dressform"), "{text}");
    assert!(text.contains("# units: mm\n# up: +z\n"), "{text}");
    // Writing what was read gives the same bytes: the rounding is stable.
    let again = Format::Obj.read(text.as_bytes()).unwrap();
    assert_eq!(Export::canonical(Format::Obj).encode(&again), text.as_bytes());
}

#[test]
fn glb_export_passes_the_khronos_validator() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("body.glb");
    let export = Export::canonical(Format::Glb).with_comments(["source: test".to_string()]);
    std::fs::write(&path, export.encode(&canonical_body())).unwrap();
    let Some(report) = crate::common::validate_gltf(&path) else { return };
    assert_eq!(report.errors, 0, "{:#}", report.json);
    assert_eq!(report.warnings, 0, "{:#}", report.json);
}
