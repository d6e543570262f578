//! Binary glTF 2.0 (`.glb`). The JSON document goes through `gltf-json`; the container (a
//! 12-byte header, a JSON chunk, a binary chunk) and the accessors are read here, every
//! offset checked against the bytes that are there.
//!
//! Read: the triangles (`mode` 4) of every mesh the scene places, each moved by its node's
//! transform; positions must be `FLOAT` `VEC3` and indices unsigned integers, all in the file's
//! own binary chunk. Comments: the strings of a `"comments"` array in the `extras` of the asset
//! and of the nodes. Write: one node, one mesh, `f32` positions, `u32` indices, the comments
//! in the asset's `extras`.

use super::{MeshFile, ReadError};
use crate::body::mesh::Mesh;
use crate::messages::quote;
use glam::{DMat4, DQuat, DVec3};
use gltf_json as json;
use json::accessor::{ComponentType, GenericComponentType, Type};
use json::validation::{Checked, USize64};

/// `glTF`, the file's first four bytes.
const MAGIC: &[u8; 4] = b"glTF";
/// The container version this reads and writes.
const VERSION: u32 = 2;
/// Chunk types: `JSON` and `BIN\0` as little-endian integers (glTF 2.0, section 4.4.3).
const JSON_CHUNK: u32 = 0x4E4F_534A;
const BIN_CHUNK: u32 = 0x004E_4942;
/// How many characters of the JSON parser's message an error shows.
const JSON_ERROR_SHOWN: usize = 120;

pub(super) fn read(bytes: &[u8]) -> Result<MeshFile, ReadError> {
    let (json_bytes, bin) = container(bytes)?;
    let root = json::Root::from_slice(json_bytes).map_err(|e| {
        ReadError::Malformed(format!(
            "the JSON chunk: {}",
            quote(e.to_string().as_bytes(), JSON_ERROR_SHOWN)
        ))
    })?;
    let mut comments = comments_in(&root.asset.extras);
    for node in &root.nodes {
        comments.extend(comments_in(&node.extras));
    }
    let mut reader = Scene { root: &root, bin, mesh: Mesh::default(), budget: bytes.len() };
    let placed = placements(&root)?;
    for (node, world) in placed {
        if let Some(mesh) = root.nodes[node].mesh {
            reader.add_mesh(mesh.value(), world)?;
        }
    }
    Ok(MeshFile { mesh: reader.mesh, comments })
}

/// The JSON chunk and the binary chunk (empty if there is none).
fn container(bytes: &[u8]) -> Result<(&[u8], &[u8]), ReadError> {
    let word =
        |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    if !bytes.starts_with(MAGIC) {
        return Err(ReadError::Malformed("a glb file starts with 'glTF'".into()));
    }
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(ReadError::Truncated("the 12-byte glb header is cut short".into()));
    };
    if version != VERSION {
        return Err(ReadError::Malformed(format!(
            "glb version {version}; dressform reads version 2"
        )));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(ReadError::Truncated(format!(
            "the header declares {length} bytes but the file has {}",
            bytes.len()
        )));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < length {
        let (Some(size), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(ReadError::Truncated(format!("a chunk header at byte {at} is cut short")));
        };
        let start = at + 8;
        let end =
            start.checked_add(size as usize).filter(|&end| end <= length).ok_or_else(|| {
                ReadError::Truncated(format!("the chunk at byte {at} reaches beyond the file"))
            })?;
        chunks.push((kind, &bytes[start..end]));
        at = end;
    }
    let json = match chunks.first() {
        Some(&(JSON_CHUNK, data)) => data,
        _ => return Err(ReadError::Malformed("the first chunk is not the JSON chunk".into())),
    };
    let bin = chunks.get(1).filter(|c| c.0 == BIN_CHUNK).map_or(&[][..], |c| c.1);
    Ok((json, bin))
}

/// The strings of a `"comments"` array in `extras`.
fn comments_in(extras: &json::Extras) -> Vec<String> {
    let Some(raw) = extras else { return Vec::new() };
    let value: serde_json::Value = serde_json::from_str(raw.get()).unwrap_or_default();
    let strings = value.get("comments").and_then(|c| c.as_array()).cloned().unwrap_or_default();
    strings.into_iter().filter_map(|s| s.as_str().map(str::to_string)).collect()
}

/// The nodes of the scene (the default one, else the first, else every node no other node
/// lists as a child) with their world transforms. Each node is placed once (a cycle of
/// children is cut).
fn placements(root: &json::Root) -> Result<Vec<(usize, DMat4)>, ReadError> {
    let n = root.nodes.len();
    let scene = root.scene.map(|s| s.value()).or((!root.scenes.is_empty()).then_some(0));
    let starts: Vec<usize> = match scene {
        Some(s) => {
            let scene = root.scenes.get(s).ok_or_else(|| missing("scene", s))?;
            scene.nodes.iter().map(|i| i.value()).collect()
        }
        None => {
            let mut child = vec![false; n];
            for c in root.nodes.iter().flat_map(|node| node.children.iter().flatten()) {
                if let Some(slot) = child.get_mut(c.value()) {
                    *slot = true;
                }
            }
            (0..n).filter(|&i| !child[i]).collect()
        }
    };
    let mut placed = Vec::new();
    let mut seen = vec![false; n];
    // Depth first, in the order the file lists the nodes.
    let mut stack: Vec<(usize, DMat4)> =
        starts.into_iter().rev().map(|i| (i, DMat4::IDENTITY)).collect();
    while let Some((i, parent)) = stack.pop() {
        let node = root.nodes.get(i).ok_or_else(|| missing("node", i))?;
        if std::mem::replace(&mut seen[i], true) {
            continue;
        }
        let world = parent * local(node);
        stack.extend(node.children.iter().flatten().rev().map(|c| (c.value(), world)));
        placed.push((i, world));
    }
    Ok(placed)
}

/// A node's own transform: its matrix, or translation * rotation * scale.
fn local(node: &json::Node) -> DMat4 {
    if let Some(m) = node.matrix {
        return DMat4::from_cols_array(&m.map(f64::from));
    }
    let t = node.translation.map_or(DVec3::ZERO, |t| DVec3::from_array(t.map(f64::from)));
    let r = node.rotation.map_or(DQuat::IDENTITY, |q| DQuat::from_array(q.0.map(f64::from)));
    let s = node.scale.map_or(DVec3::ONE, |s| DVec3::from_array(s.map(f64::from)));
    DMat4::from_scale_rotation_translation(s, r.normalize(), t)
}

fn missing(what: &str, index: usize) -> ReadError {
    ReadError::Malformed(format!("{what} {index} does not exist"))
}

/// The mesh being gathered from the scene.
struct Scene<'a> {
    root: &'a json::Root,
    bin: &'a [u8],
    mesh: Mesh,
    /// Vertices and indices still allowed: the file's size, so that a mesh placed by many
    /// nodes cannot make a small file expand without bound.
    budget: usize,
}

impl<'a> Scene<'a> {
    fn add_mesh(&mut self, index: usize, world: DMat4) -> Result<(), ReadError> {
        let mesh = self.root.meshes.get(index).ok_or_else(|| missing("mesh", index))?;
        for primitive in &mesh.primitives {
            if primitive.mode != Checked::Valid(json::mesh::Mode::Triangles) {
                continue;
            }
            let position =
                primitive.attributes.get(&Checked::Valid(json::mesh::Semantic::Positions));
            let position = position.ok_or_else(|| {
                ReadError::Malformed(format!("a primitive of mesh {index} has no POSITION"))
            })?;
            let corners = self.accessor(position.value(), Type::Vec3)?;
            if corners.kind != ComponentType::F32 {
                return Err(ReadError::Malformed("POSITION must be FLOAT".into()));
            }
            let base = self.mesh.positions.len();
            let count = corners.count;
            let vertices = (0..count).map(|k| {
                let c = |i| f64::from(f32::from_le_bytes(corners.component(k, i)));
                world.transform_point3(DVec3::new(c(0), c(1), c(2)))
            });
            self.mesh.positions.extend(vertices);
            let indices: Vec<u64> = match primitive.indices {
                Some(i) => {
                    let list = self.accessor(i.value(), Type::Scalar)?;
                    (0..list.count).map(|k| list.integer(k)).collect::<Result<_, _>>()?
                }
                None => (0..count as u64).collect(),
            };
            if let Some(&bad) = indices.iter().find(|&&i| i >= count as u64) {
                return Err(ReadError::Malformed(format!(
                    "mesh {index} refers to vertex {bad}, but its primitive has {count}"
                )));
            }
            let global = |i: u64| u32::try_from(base as u64 + i).ok();
            for t in indices.chunks_exact(3) {
                let tri = [global(t[0]), global(t[1]), global(t[2])];
                let [Some(a), Some(b), Some(c)] = tri else {
                    return Err(ReadError::Malformed("more than 4 billion vertices".into()));
                };
                self.mesh.triangles.push([a, b, c]);
            }
        }
        Ok(())
    }

    /// The data of accessor `index`, which must be of type `expected`, checked against the
    /// binary chunk and charged to the budget.
    fn accessor(&mut self, index: usize, expected: Type) -> Result<Accessor<'a>, ReadError> {
        let (root, bin): (&'a json::Root, &'a [u8]) = (self.root, self.bin);
        let a = root.accessors.get(index).ok_or_else(|| missing("accessor", index))?;
        let bad = |why: &str| ReadError::Malformed(format!("accessor {index}: {why}"));
        if a.type_ != Checked::Valid(expected) {
            return Err(bad(&format!("expected a {expected:?}")));
        }
        if a.sparse.is_some() {
            return Err(bad("sparse accessors are not supported"));
        }
        let Checked::Valid(GenericComponentType(kind)) = a.component_type else {
            return Err(bad("unknown component type"));
        };
        let view = a.buffer_view.ok_or_else(|| bad("no buffer view"))?.value();
        let view = root.buffer_views.get(view).ok_or_else(|| missing("buffer view", view))?;
        let buffer = root.buffers.get(view.buffer.value());
        if view.buffer.value() != 0 || buffer.is_none_or(|b| b.uri.is_some()) {
            return Err(bad("its data is not in the glb file's binary chunk"));
        }
        let span = |offset: Option<USize64>, length: u64| {
            let start = offset.map_or(0, |o| o.0);
            start.checked_add(length).map(|end| (start, end))
        };
        let (start, end) =
            span(view.byte_offset, view.byte_length.0).ok_or_else(|| bad("overflow"))?;
        let data = usize::try_from(start)
            .ok()
            .zip(usize::try_from(end).ok())
            .and_then(|(s, e)| bin.get(s..e))
            .ok_or_else(|| bad("its buffer view reaches beyond the binary chunk"))?;
        let size = kind.size() * expected.multiplicity();
        let stride = view.byte_stride.map_or(size, |s| s.0);
        let count = usize::try_from(a.count.0).map_err(|_| bad("too many elements"))?;
        let offset = usize::try_from(a.byte_offset.map_or(0, |o| o.0)).unwrap_or(usize::MAX);
        let last = count
            .checked_sub(1)
            .map(|k| k.checked_mul(stride).and_then(|s| s.checked_add(offset)?.checked_add(size)));
        if stride < size || last.is_some_and(|end| end.is_none_or(|end| end > data.len())) {
            return Err(bad("its elements reach beyond its buffer view"));
        }
        self.budget = self.budget.checked_sub(count).ok_or_else(|| {
            ReadError::Malformed(
                "the scene places its meshes more often than the file could hold".into(),
            )
        })?;
        Ok(Accessor { data: &data[offset.min(data.len())..], stride, count, kind })
    }
}

/// An accessor's elements, bounds-checked.
struct Accessor<'a> {
    data: &'a [u8],
    stride: usize,
    count: usize,
    kind: ComponentType,
}

impl Accessor<'_> {
    /// Component `i` of element `k`, as 4 bytes.
    fn component(&self, k: usize, i: usize) -> [u8; 4] {
        let at = k * self.stride + 4 * i;
        [self.data[at], self.data[at + 1], self.data[at + 2], self.data[at + 3]]
    }

    /// Element `k` of an index accessor.
    fn integer(&self, k: usize) -> Result<u64, ReadError> {
        let at = k * self.stride;
        let d = &self.data[at..];
        Ok(match self.kind {
            ComponentType::U8 => d[0].into(),
            ComponentType::U16 => u16::from_le_bytes([d[0], d[1]]).into(),
            ComponentType::U32 => u32::from_le_bytes([d[0], d[1], d[2], d[3]]).into(),
            _ => return Err(ReadError::Malformed("indices must be unsigned integers".into())),
        })
    }
}

/// One node with one mesh: `f32` positions (with the bounds glTF requires), `u32` indices,
/// `comments` in the asset's `extras`.
pub(super) fn encode(mesh: &Mesh, comments: &[String]) -> Vec<u8> {
    let mut root = json::Root::default();
    root.asset.generator = Some(format!("dressform {}", env!("CARGO_PKG_VERSION")));
    let extras = serde_json::json!({ "comments": comments }).to_string();
    root.asset.extras = json::extras::RawValue::from_string(extras).ok();
    let mut bin: Vec<u8> = Vec::with_capacity(12 * (mesh.positions.len() + mesh.triangles.len()));
    if !mesh.triangles.is_empty() {
        let points: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.as_vec3().to_array()).collect();
        bin.extend(points.iter().flatten().flat_map(|c| c.to_le_bytes()));
        let positions_length = bin.len();
        bin.extend(mesh.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
        let buffer = root.push(json::Buffer {
            name: None,
            byte_length: USize64::from(bin.len()),
            extensions: None,
            extras: None,
            uri: None,
        });
        let view = |root: &mut json::Root, offset: usize, length: usize, target| {
            root.push(json::buffer::View {
                name: None,
                buffer,
                byte_length: USize64::from(length),
                byte_offset: Some(USize64::from(offset)),
                byte_stride: None,
                extensions: None,
                extras: None,
                target: Some(Checked::Valid(target)),
            })
        };
        let positions_view =
            view(&mut root, 0, positions_length, json::buffer::Target::ArrayBuffer);
        let indices_view = view(
            &mut root,
            positions_length,
            bin.len() - positions_length,
            json::buffer::Target::ElementArrayBuffer,
        );
        let bound = |pick: fn(f32, f32) -> f32, start: f32| {
            let b = points.iter().fold([start; 3], |b, p| [0, 1, 2].map(|k| pick(b[k], p[k])));
            json::Value::from(Vec::from(b))
        };
        let accessor = |root: &mut json::Root, view, count, kind, type_, min, max| {
            root.push(json::Accessor {
                name: None,
                buffer_view: Some(view),
                byte_offset: None,
                count: USize64::from(count),
                component_type: Checked::Valid(GenericComponentType(kind)),
                extensions: None,
                extras: None,
                type_: Checked::Valid(type_),
                min,
                max,
                normalized: false,
                sparse: None,
            })
        };
        let min = Some(bound(f32::min, f32::INFINITY));
        let max = Some(bound(f32::max, f32::NEG_INFINITY));
        let positions = accessor(
            &mut root,
            positions_view,
            points.len(),
            ComponentType::F32,
            Type::Vec3,
            min,
            max,
        );
        let indices = accessor(
            &mut root,
            indices_view,
            3 * mesh.triangles.len(),
            ComponentType::U32,
            Type::Scalar,
            None,
            None,
        );
        let primitive = json::mesh::Primitive {
            attributes: [(Checked::Valid(json::mesh::Semantic::Positions), positions)].into(),
            extensions: None,
            extras: None,
            indices: Some(indices),
            material: None,
            mode: Checked::Valid(json::mesh::Mode::Triangles),
            targets: None,
        };
        let mesh = root.push(json::Mesh {
            name: None,
            extensions: None,
            extras: None,
            primitives: vec![primitive],
            weights: None,
        });
        let node = root.push(json::Node { mesh: Some(mesh), ..Default::default() });
        let scene = root.push(json::Scene {
            extensions: None,
            extras: None,
            name: None,
            nodes: vec![node],
        });
        root.scene = Some(scene);
    }
    // Serialising a document built above into memory cannot fail.
    let mut document = root.to_vec().unwrap_or_default();
    document.resize(document.len().next_multiple_of(4), b' ');
    let length = 12 + 8 + document.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::with_capacity(length);
    out.extend_from_slice(MAGIC);
    for word in [VERSION, length as u32, document.len() as u32, JSON_CHUNK] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&document);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&BIN_CHUNK.to_le_bytes());
        out.extend_from_slice(&bin);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::mesh::shapes::add_tetrahedron;

    #[test]
    fn round_trip_with_comments() {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::new(0.5, -0.25, 1.0), 2.0);
        let bytes = encode(&mesh, &["units: m".into(), "up: +y".into()]);
        assert_eq!(bytes.len() % 4, 0);
        let file = read(&bytes).unwrap();
        assert_eq!(file.mesh, mesh);
        assert_eq!(file.comments, ["units: m", "up: +y"]);
    }

    #[test]
    fn cut_and_out_of_range_files_are_refused() {
        let mut mesh = Mesh::default();
        add_tetrahedron(&mut mesh, DVec3::ZERO, 1.0);
        let bytes = encode(&mesh, &[]);
        for cut in [3, 11, 20, bytes.len() - 1] {
            assert!(read(&bytes[..cut]).is_err(), "{cut}");
        }
        let mut bad = bytes.clone();
        let at = bad.len() - 4; // the last index
        bad[at..].copy_from_slice(&99u32.to_le_bytes());
        let e = read(&bad).unwrap_err().to_string();
        assert!(e.contains("refers to vertex 99"), "{e}");
    }
}
