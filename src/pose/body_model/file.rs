//! The model file: glTF 2.0 binary (`.glb`), written with `gltf-json`.
//!
//! - the mean body is the mesh (`POSITION`, `f32`), the template's triangles its indices;
//! - the k shape components are morph targets, scaled by their standard deviations (a morph
//!   weight is beta, in units of sigma), quantised to normalised `i16` (`KHR_mesh_quantization`:
//!   a step of 1/32767 m = 0.031 mm per sigma) and named in `mesh.extras.targetNames`;
//! - the skeleton is a skin: one node per bone at its rest joint, inverse bind matrices,
//!   `JOINTS_0`/`WEIGHTS_0` (weights are multiples of 2^-16, exact in `f32`);
//! - the MVC regressor (joints x vertices, `f32`) and the mirror map are accessors named in the
//!   root's `extras.dressform_body_model`, with k, the standard deviations, the explained
//!   variance, units, the angle convention and how the model was built.
//!
//! glTF is metres, Y up, facing +Z (MakeHuman's own frame); the model is read back into the
//! canonical frame (mm, Z up, facing -Y). [`at_file_precision`] rounds a model as the file
//! stores it, so `read(write(m)) == at_file_precision(m)` exactly.

use super::{BodyModel, Provenance, Skeleton};
use crate::pose::skinning::SkinWeights;
use glam::DVec3;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Millimetres per glTF unit (metres).
const MM_PER_METRE: f64 = 1000.0;
/// The largest normalised `i16` (glTF: value = max(c / 32767, -1)).
const I16_SCALE: f64 = 32767.0;
/// The format name and version in `extras`.
pub const FORMAT: &str = "dressform-body-model/1";
/// The key of the model's metadata in the root's `extras`.
const EXTRAS_KEY: &str = "dressform_body_model";
/// Buffer views of vertex attributes.
const VERTICES: Option<json::buffer::Target> = Some(json::buffer::Target::ArrayBuffer);
/// The extension the quantised morph targets need.
const QUANTIZATION: &str = "KHR_mesh_quantization";

/// Why a model file cannot be read or written.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", file.display())]
pub struct FileError {
    /// The file.
    pub file: PathBuf,
    /// What is wrong (one line).
    pub problem: String,
}

/// The model's metadata, in the root's `extras.dressform_body_model`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metadata {
    /// [`FORMAT`].
    pub format: String,
    /// The number of shape components (morph targets).
    pub components: usize,
    /// Each component's standard deviation (mm, over the whole body vector).
    pub standard_deviations_mm: Vec<f64>,
    /// The fraction of the population's variance each component explains.
    pub explained_variance: Vec<f64>,
    /// Bone names, in skin-joint order.
    pub bones: Vec<String>,
    /// Accessor of the MVC joint regressor: joints x vertices, row-major (eq. 1).
    pub joint_regressor: u32,
    /// Accessor of the mirror map: each vertex's partner about the symmetry plane.
    pub mirror_map: u32,
    /// Units, frame, rest pose and angle convention, in words.
    pub conventions: String,
    /// How the model was built.
    pub built_from: Provenance,
}

const CONVENTIONS: &str = "glTF metres, Y up, facing +Z (dressform reads it as mm, Z up, facing -Y); \
morph weights are shape coefficients beta in standard deviations; rest pose: MakeHuman's A-pose; \
bone rotations: rotation vectors in the rest frame's axes about each bone's joint, relative to its parent";

/// A canonical point (mm, Z up, facing -Y) in glTF's frame (m, Y up, facing +Z).
fn to_gltf(p: DVec3) -> [f64; 3] {
    [p.x / MM_PER_METRE, p.z / MM_PER_METRE, -p.y / MM_PER_METRE]
}

/// A glTF point back in the canonical frame.
fn from_gltf(g: [f64; 3]) -> DVec3 {
    DVec3::new(g[0], -g[2], g[1]) * MM_PER_METRE
}

/// A canonical point as the file stores it (`f32` metres).
fn round_f32(p: DVec3) -> DVec3 {
    from_gltf(to_gltf(p).map(|c| f64::from(c as f32)))
}

/// A shape offset's stored `i16` (normalised metres).
fn quantise(d: DVec3) -> [i16; 3] {
    to_gltf(d).map(|c| (c * I16_SCALE).round().clamp(-I16_SCALE, I16_SCALE) as i16)
}

fn dequantise(q: [i16; 3]) -> DVec3 {
    from_gltf(q.map(|c| (f64::from(c) / I16_SCALE).max(-1.0)))
}

/// `model` rounded as the file stores it: positions `f32`, components `i16`, regressor `f32`
/// (skin weights are already exact). Idempotent.
pub fn at_file_precision(mut model: BodyModel) -> BodyModel {
    model.mean.iter_mut().for_each(|p| *p = round_f32(*p));
    for c in &mut model.components {
        c.iter_mut().for_each(|d| *d = dequantise(quantise(*d)));
    }
    for row in &mut model.regressor {
        row.iter_mut().for_each(|w| *w = f64::from(*w as f32));
    }
    model
}

/// The binary chunk under construction, and the JSON that describes it.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// Appends `bytes` as a buffer view (4-byte aligned) and an accessor over it.
    #[allow(clippy::too_many_arguments)]
    fn accessor(
        &mut self,
        bytes: &[u8],
        count: usize,
        component: json::accessor::ComponentType,
        kind: json::accessor::Type,
        normalized: bool,
        stride: Option<usize>,
        bounds: Option<(Vec<f64>, Vec<f64>)>,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(self.bin.len())),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: None,
        });
        self.bin.extend_from_slice(bytes);
        let (min, max) = match bounds {
            Some((lo, hi)) => (Some(json::Value::from(lo)), Some(json::Value::from(hi))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: None,
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// `JOINTS_0` (`u8`) and `WEIGHTS_0` (`f32`) of `weights`, four slots per vertex.
    fn skin_attributes(
        &mut self,
        weights: &SkinWeights,
    ) -> (json::Index<json::Accessor>, json::Index<json::Accessor>) {
        use json::accessor::{ComponentType as C, Type as T};
        let (mut joints, mut values) = (Vec::new(), Vec::new());
        for v in 0..weights.len() {
            let mut slots: Vec<(usize, f64)> = weights.of(v).collect();
            slots.resize(4, (0, 0.0));
            joints.extend(slots.iter().map(|&(bone, _)| bone as u8));
            values.extend(slots.iter().flat_map(|&(_, w)| (w as f32).to_le_bytes()));
        }
        let n = weights.len();
        (
            self.accessor(&joints, n, C::U8, T::Vec4, false, None, None, VERTICES),
            self.accessor(&values, n, C::F32, T::Vec4, false, None, None, VERTICES),
        )
    }

    /// The skeleton as a skin: one node per bone at its joint `at` (canonical frame; relative
    /// to the parent), inverse binds -joint. Returns the skin and the root bone's node.
    fn skeleton(
        &mut self,
        skeleton: &Skeleton,
        at: &[DVec3],
    ) -> (json::Index<json::Skin>, json::Index<json::Node>) {
        use json::accessor::{ComponentType as C, Type as T};
        let first_bone = self.root.nodes.len() as u32;
        let mut children: Vec<Vec<json::Index<json::Node>>> = vec![Vec::new(); at.len()];
        for (l, parent) in skeleton.parents.iter().enumerate() {
            if let Some(p) = parent {
                children[*p].push(json::Index::new(first_bone + l as u32));
            }
        }
        for (l, name) in skeleton.names.iter().enumerate() {
            let above = skeleton.parents[l].map_or(DVec3::ZERO, |p| at[p]);
            let offset = to_gltf(at[l])
                .iter()
                .zip(to_gltf(above))
                .map(|(a, b)| (a - b) as f32)
                .collect::<Vec<_>>();
            self.root.push(json::Node {
                name: Some(name.clone()),
                translation: Some([offset[0], offset[1], offset[2]]),
                children: Some(std::mem::take(&mut children[l])).filter(|c| !c.is_empty()),
                ..Default::default()
            });
        }
        let inverse_binds: Vec<u8> = at
            .iter()
            .flat_map(|&j| {
                let t = to_gltf(j).map(|c| -c as f32);
                let mut m = glam::Mat4::IDENTITY.to_cols_array();
                m[12..15].copy_from_slice(&t);
                m.into_iter().flat_map(f32::to_le_bytes).collect::<Vec<_>>()
            })
            .collect();
        let ibm = self.accessor(&inverse_binds, at.len(), C::F32, T::Mat4, false, None, None, None);
        let bones: Vec<json::Index<json::Node>> =
            (0..at.len() as u32).map(|l| json::Index::new(first_bone + l)).collect();
        let root_bone = bones[skeleton.parents.iter().position(Option::is_none).unwrap_or(0)];
        let skin = self.root.push(json::Skin {
            extensions: None,
            extras: None,
            inverse_bind_matrices: Some(ibm),
            joints: bones,
            name: Some("skeleton".into()),
            skeleton: Some(root_bone),
        });
        (skin, root_bone)
    }

    /// The `.glb` bytes: the binary chunk padded, its buffer declared.
    fn finish(mut self) -> Vec<u8> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.buffers.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        let json_bytes = serde_json::to_vec(&self.root).unwrap_or_default();
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
            json: json_bytes.into(),
            bin: Some(self.bin.into()),
        };
        glb.to_vec().unwrap_or_default()
    }
}

/// Per-axis bounds of glTF points, as the file stores them.
fn bounds(points: impl Iterator<Item = [f64; 3]>) -> (Vec<f64>, Vec<f64>) {
    let (mut lo, mut hi) = (vec![f64::INFINITY; 3], vec![f64::NEG_INFINITY; 3]);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

fn raw_value(value: &impl Serialize) -> json::extras::Extras {
    serde_json::value::to_raw_value(value).ok()
}

/// The model as `.glb` bytes (at [`at_file_precision`]).
pub fn to_bytes(model: &BodyModel) -> Vec<u8> {
    use json::accessor::{ComponentType as C, Type as T};
    let model = at_file_precision(model.clone());
    let mut b = Builder { root: json::Root::default(), bin: Vec::new() };
    let gltf_mean: Vec<[f64; 3]> = model.mean.iter().map(|&p| to_gltf(p)).collect();
    let position_bytes: Vec<u8> =
        gltf_mean.iter().flatten().flat_map(|&c| (c as f32).to_le_bytes()).collect();
    let positions = b.accessor(
        &position_bytes,
        model.mean.len(),
        C::F32,
        T::Vec3,
        false,
        None,
        Some(bounds(gltf_mean.iter().copied())),
        VERTICES,
    );
    let index_bytes: Vec<u8> =
        model.triangles.iter().flatten().flat_map(|&i| i.to_le_bytes()).collect();
    let indices = b.accessor(
        &index_bytes,
        model.triangles.len() * 3,
        C::U32,
        T::Scalar,
        false,
        None,
        None,
        Some(json::buffer::Target::ElementArrayBuffer),
    );
    let bound = b.skin_attributes(&model.weights);
    let targets: Vec<json::mesh::MorphTarget> = model
        .components
        .iter()
        .map(|component| {
            let q: Vec<[i16; 3]> = component.iter().map(|&d| quantise(d)).collect();
            // Each element padded to 8 bytes: vertex attributes are 4-byte aligned.
            let bytes: Vec<u8> = q
                .iter()
                .flat_map(|e| {
                    e.iter().chain(&[0]).flat_map(|c| c.to_le_bytes()).collect::<Vec<_>>()
                })
                .collect();
            // The bounds of a normalised accessor are its stored integers.
            let stored = q.iter().map(|e| e.map(f64::from));
            let accessor = b.accessor(
                &bytes,
                q.len(),
                C::I16,
                T::Vec3,
                true,
                Some(8),
                Some(bounds(stored)),
                VERTICES,
            );
            json::mesh::MorphTarget { positions: Some(accessor), normals: None, tangents: None }
        })
        .collect();
    let names: Vec<String> = (0..model.k()).map(|c| format!("beta{c}")).collect();
    let mesh = b.root.push(json::Mesh {
        extensions: None,
        extras: raw_value(&serde_json::json!({ "targetNames": names })),
        name: Some("body".into()),
        primitives: vec![skinned_triangles(positions, indices, bound, Some(targets))],
        weights: Some(vec![0.0; model.k()]),
    });
    let rest = model.regress_joints(&model.mean).into_iter().map(round_f32).collect::<Vec<_>>();
    let (skin, root_bone) = b.skeleton(&model.skeleton, &rest);
    let body = b.root.push(json::Node {
        name: Some("body".into()),
        mesh: Some(mesh),
        skin: Some(skin),
        ..Default::default()
    });
    let regressor_bytes: Vec<u8> =
        model.regressor.iter().flatten().flat_map(|&w| (w as f32).to_le_bytes()).collect();
    let regressor = b.accessor(
        &regressor_bytes,
        model.regressor.len() * model.mean.len(),
        C::F32,
        T::Scalar,
        false,
        None,
        None,
        None,
    );
    let mirror_bytes: Vec<u8> = model.mirror.iter().flat_map(|m| m.to_le_bytes()).collect();
    let mirror =
        b.accessor(&mirror_bytes, model.mirror.len(), C::U32, T::Scalar, false, None, None, None);
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: None,
        nodes: vec![body, root_bone],
    });
    b.root.scene = Some(scene);
    let metadata = Metadata {
        format: FORMAT.into(),
        components: model.k(),
        standard_deviations_mm: model.sigmas.clone(),
        explained_variance: model.explained.clone(),
        bones: model.skeleton.names.clone(),
        joint_regressor: regressor.value() as u32,
        mirror_map: mirror.value() as u32,
        conventions: CONVENTIONS.into(),
        built_from: model.provenance.clone(),
    };
    b.root.extras = raw_value(&serde_json::json!({ EXTRAS_KEY: metadata }));
    b.root.extensions_used = vec![QUANTIZATION.into()];
    b.root.extensions_required = vec![QUANTIZATION.into()];
    b.root.asset = json::Asset {
        generator: Some(format!("dressform {}", env!("CARGO_PKG_VERSION"))),
        copyright: Some("Derived from the MakeHuman assets (CC0 1.0)".into()),
        ..Default::default()
    };
    b.finish()
}

/// One primitive of triangles bound to a skeleton: positions, indices and the skin's
/// `(JOINTS_0, WEIGHTS_0)` accessors, with the model's morph targets if any.
fn skinned_triangles(
    positions: json::Index<json::Accessor>,
    indices: json::Index<json::Accessor>,
    (joints_0, weights_0): (json::Index<json::Accessor>, json::Index<json::Accessor>),
    targets: Option<Vec<json::mesh::MorphTarget>>,
) -> json::mesh::Primitive {
    json::mesh::Primitive {
        attributes: BTreeMap::from([
            (Valid(json::mesh::Semantic::Positions), positions),
            (Valid(json::mesh::Semantic::Joints(0)), joints_0),
            (Valid(json::mesh::Semantic::Weights(0)), weights_0),
        ]),
        extensions: None,
        extras: None,
        indices: Some(indices),
        material: None,
        mode: Valid(json::mesh::Mode::Triangles),
        targets,
    }
}

/// A scan rigged with a skeleton as `.glb` (metres, Y up, facing +Z): the mesh bound as it
/// stands, with `weights` (at most four bones per vertex), the bones at `joints` (canonical
/// frame, mm; the fitted pose's joints). Moving a bone's node re-poses the scan (eq. 3).
pub fn rigged_to_bytes(
    mesh: &crate::body::mesh::Mesh,
    weights: &SkinWeights,
    skeleton: &Skeleton,
    joints: &[DVec3],
) -> Vec<u8> {
    use json::accessor::{ComponentType as C, Type as T};
    let mut b = Builder { root: json::Root::default(), bin: Vec::new() };
    let stored: Vec<[f32; 3]> =
        mesh.positions.iter().map(|&p| to_gltf(p).map(|c| c as f32)).collect();
    let position_bytes: Vec<u8> = stored.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let extent = bounds(stored.iter().map(|p| p.map(f64::from)));
    let n = stored.len();
    let positions =
        b.accessor(&position_bytes, n, C::F32, T::Vec3, false, None, Some(extent), VERTICES);
    let index_bytes: Vec<u8> =
        mesh.triangles.iter().flatten().flat_map(|&i| i.to_le_bytes()).collect();
    let target = Some(json::buffer::Target::ElementArrayBuffer);
    let count = mesh.triangles.len() * 3;
    let indices = b.accessor(&index_bytes, count, C::U32, T::Scalar, false, None, None, target);
    let bound = b.skin_attributes(weights);
    let body_mesh = b.root.push(json::Mesh {
        extensions: None,
        extras: None,
        name: Some("scan".into()),
        primitives: vec![skinned_triangles(positions, indices, bound, None)],
        weights: None,
    });
    let at: Vec<DVec3> = joints.iter().map(|&j| round_f32(j)).collect();
    let (skin, root_bone) = b.skeleton(skeleton, &at);
    let body = b.root.push(json::Node {
        name: Some("scan".into()),
        mesh: Some(body_mesh),
        skin: Some(skin),
        ..Default::default()
    });
    let scene = b.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: None,
        nodes: vec![body, root_bone],
    });
    b.root.scene = Some(scene);
    b.root.asset = json::Asset {
        generator: Some(format!("dressform {}", env!("CARGO_PKG_VERSION"))),
        ..Default::default()
    };
    b.finish()
}

/// Writes `model` to `path` atomically.
pub fn write(model: &BodyModel, path: &Path) -> Result<(), crate::atomic_output::WriteError> {
    crate::atomic_output::write_atomically(path, &to_bytes(model))
}

/// Reads a model file.
pub fn read(path: &Path) -> Result<BodyModel, FileError> {
    let bytes = std::fs::read(path)
        .map_err(|e| FileError { file: path.into(), problem: format!("cannot read: {e}") })?;
    from_bytes(&bytes).map_err(|problem| FileError { file: path.into(), problem })
}

/// An accessor's elements as `f64` (normalised integers mapped to [-1, 1] or [0, 1]).
fn accessor(
    root: &json::Root,
    bin: &[u8],
    index: usize,
    what: &str,
) -> Result<(Vec<f64>, usize), String> {
    use json::accessor::ComponentType as C;
    let a = root.accessors.get(index).ok_or_else(|| format!("{what}: no accessor {index}"))?;
    let (Valid(component), Valid(kind)) = (&a.component_type, &a.type_) else {
        return Err(format!("{what}: accessor {index} has an unknown type"));
    };
    let view = a
        .buffer_view
        .and_then(|v| root.buffer_views.get(v.value()))
        .ok_or_else(|| format!("{what}: accessor {index} has no buffer view"))?;
    let size = component.0.size();
    let width = kind.multiplicity();
    let stride = view.byte_stride.map_or(size * width, |s| s.0);
    let start =
        view.byte_offset.map_or(0, |o| o.0 as usize) + a.byte_offset.map_or(0, |o| o.0 as usize);
    let count = a.count.0 as usize;
    let end = start + stride * count.saturating_sub(1) + size * width;
    if count > 0
        && end
            > bin.len().min(
                start + view.byte_length.0 as usize + a.byte_offset.map_or(0, |o| o.0 as usize),
            )
    {
        return Err(format!("{what}: accessor {index} runs past its buffer"));
    }
    let mut out = Vec::with_capacity(count * width);
    for e in 0..count {
        for c in 0..width {
            let at = start + e * stride + c * size;
            let b = &bin[at..at + size];
            let value = match component.0 {
                C::I8 => f64::from(b[0] as i8),
                C::U8 => f64::from(b[0]),
                C::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                C::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                C::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                C::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            };
            out.push(match (a.normalized, component.0) {
                (true, C::I8) => (value / 127.0).max(-1.0),
                (true, C::U8) => value / 255.0,
                (true, C::I16) => (value / I16_SCALE).max(-1.0),
                (true, C::U16) => value / 65535.0,
                _ => value,
            });
        }
    }
    Ok((out, width))
}

fn points(values: &[f64]) -> Vec<DVec3> {
    values.chunks_exact(3).map(|c| from_gltf([c[0], c[1], c[2]])).collect()
}

/// Parses `.glb` bytes written by [`to_bytes`].
pub fn from_bytes(bytes: &[u8]) -> Result<BodyModel, String> {
    let glb =
        gltf::binary::Glb::from_slice(bytes).map_err(|e| format!("not a glTF binary file: {e}"))?;
    let root: json::Root =
        serde_json::from_slice(&glb.json).map_err(|e| format!("unreadable glTF JSON: {e}"))?;
    let bin = glb.bin.as_deref().unwrap_or_default();
    let extras: serde_json::Value =
        root.extras.as_ref().and_then(|r| serde_json::from_str(r.get()).ok()).unwrap_or_default();
    let meta: Metadata = serde_json::from_value(extras[EXTRAS_KEY].clone())
        .map_err(|e| format!("not a dressform body model (extras.{EXTRAS_KEY}: {e})"))?;
    if meta.format != FORMAT {
        return Err(format!(
            "extras.{EXTRAS_KEY}.format is {:?}, this dressform reads {FORMAT:?}",
            meta.format
        ));
    }
    let primitive = root.meshes.first().and_then(|m| m.primitives.first()).ok_or("no mesh")?;
    let attribute = |s: json::mesh::Semantic| {
        primitive
            .attributes
            .get(&Valid(s.clone()))
            .map(|i| i.value())
            .ok_or(format!("the mesh has no {s:?}"))
    };
    let mean =
        points(&accessor(&root, bin, attribute(json::mesh::Semantic::Positions)?, "POSITION")?.0);
    let n = mean.len();
    let flat_indices = accessor(
        &root,
        bin,
        primitive.indices.ok_or("the mesh has no indices")?.value(),
        "indices",
    )?
    .0;
    if flat_indices.iter().any(|&i| i as usize >= n) {
        return Err("a triangle refers to a vertex beyond the mesh".into());
    }
    let triangles =
        flat_indices.chunks_exact(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect();
    let targets = primitive.targets.as_deref().unwrap_or_default();
    if targets.len() != meta.components || meta.standard_deviations_mm.len() != meta.components {
        return Err(format!(
            "{} morph targets and {} standard deviations for {} components",
            targets.len(),
            meta.standard_deviations_mm.len(),
            meta.components
        ));
    }
    let components = targets
        .iter()
        .enumerate()
        .map(|(c, t)| {
            let i = t.positions.ok_or(format!("morph target {c} has no POSITION"))?.value();
            let d = points(&accessor(&root, bin, i, "morph target")?.0);
            (d.len() == n)
                .then_some(d)
                .ok_or(format!("morph target {c} has {} vertices, not {n}", 0))
        })
        .collect::<Result<Vec<_>, String>>()?;
    // Finite values and |beta| <= MAX_BETA keep every body finite: nothing writes NaN or inf.
    if let Some(v) = mean.iter().position(|p| !p.is_finite()) {
        return Err(format!("POSITION of vertex {v} is not finite"));
    }
    if let Some(c) = components.iter().position(|d| d.iter().any(|p| !p.is_finite())) {
        return Err(format!("morph target {c} has a coordinate that is not finite"));
    }
    let skin = root.skins.first().ok_or("no skin")?;
    let bone_nodes: Vec<usize> = skin.joints.iter().map(|j| j.value()).collect();
    let mut parents = vec![None; bone_nodes.len()];
    for (l, &node) in bone_nodes.iter().enumerate() {
        for child in root.nodes.get(node).and_then(|n| n.children.as_ref()).into_iter().flatten() {
            if let Some(c) = bone_nodes.iter().position(|&b| b == child.value()) {
                parents[c] = Some(l);
            }
        }
    }
    if parents.iter().enumerate().any(|(l, p)| p.is_some_and(|p| p >= l))
        || meta.bones.len() != bone_nodes.len()
    {
        return Err("the skin's joints must list parents before children, one per bone".into());
    }
    let joints = accessor(&root, bin, attribute(json::mesh::Semantic::Joints(0))?, "JOINTS_0")?.0;
    let weights =
        accessor(&root, bin, attribute(json::mesh::Semantic::Weights(0))?, "WEIGHTS_0")?.0;
    if joints.len() != 4 * n
        || weights.len() != 4 * n
        || joints.iter().any(|&j| j as usize >= bone_nodes.len())
    {
        return Err("JOINTS_0/WEIGHTS_0 need 4 valid bones and weights per vertex".into());
    }
    let per_vertex = (0..n)
        .map(|v| {
            (0..4)
                .map(|s| (joints[4 * v + s] as usize, weights[4 * v + s]))
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect();
    let regressor_flat = accessor(&root, bin, meta.joint_regressor as usize, "joint regressor")?.0;
    if regressor_flat.len() != n * bone_nodes.len() {
        return Err(format!(
            "the joint regressor has {} weights, not {}",
            regressor_flat.len(),
            n * bone_nodes.len()
        ));
    }
    let mirror: Vec<u32> = accessor(&root, bin, meta.mirror_map as usize, "mirror map")?
        .0
        .iter()
        .map(|&m| m as u32)
        .collect();
    if mirror.len() != n || mirror.iter().any(|&m| m as usize >= n) {
        return Err("the mirror map needs one partner per vertex".into());
    }
    Ok(BodyModel {
        triangles,
        mirror,
        mean,
        components,
        sigmas: meta.standard_deviations_mm,
        explained: meta.explained_variance,
        skeleton: Skeleton { names: meta.bones, parents },
        weights: SkinWeights::normalised(per_vertex),
        regressor: regressor_flat.chunks_exact(n).map(<[f64]>::to_vec).collect(),
        provenance: meta.built_from,
    })
}
