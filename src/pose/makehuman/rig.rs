//! `rigs/default.mhskel`: MakeHuman's default skeleton, 163 bones. Each bone runs from a head
//! joint to a tail joint; a joint is the mean of a list of base-mesh vertices (mostly of the
//! small `joint-*` helper cubes), so it follows the body when targets change it.

use super::{MakeHumanError, read_text};
use glam::DVec3;
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// One bone of the rig.
#[derive(Debug, Clone, PartialEq)]
pub struct Bone {
    /// MakeHuman's name (`upperarm01.L`; `.L` is the subject's left, +X).
    pub name: String,
    /// Index of the parent bone in [`Rig::bones`] (always lower), `None` for the root.
    pub parent: Option<usize>,
    /// The joint it rotates about (index into [`Rig::joints`]).
    pub head: usize,
    /// The joint at its end.
    pub tail: usize,
}

/// The rig: bones with parents before children, and joints as vertex lists.
#[derive(Debug, Clone, PartialEq)]
pub struct Rig {
    /// Bones in hierarchy order (a parent before its children; siblings by name).
    pub bones: Vec<Bone>,
    /// Joints: a name and the vertices (of the full list) whose mean is its position.
    pub joints: Vec<(String, Vec<u32>)>,
}

#[derive(Deserialize)]
struct FileBone {
    head: String,
    tail: String,
    parent: Option<String>,
}

#[derive(Deserialize)]
struct FileRig {
    bones: BTreeMap<String, FileBone>,
    joints: BTreeMap<String, Vec<u32>>,
}

impl Rig {
    /// Reads `file`; joints must list at least one vertex below `vertex_count`, bones must name
    /// existing joints and parents, and the hierarchy must be a tree.
    pub fn load(file: &Path, vertex_count: usize) -> Result<Self, MakeHumanError> {
        let bad = |what: String| MakeHumanError::new(file, what);
        let parsed: FileRig = serde_json::from_str(&read_text(file)?)
            .map_err(|e| bad(format!("not a MakeHuman skeleton: {e}")))?;
        let mut joints = Vec::new();
        let mut joint_index = HashMap::new();
        for (name, vertices) in parsed.joints {
            if vertices.is_empty() || vertices.iter().any(|&v| v as usize >= vertex_count) {
                return Err(bad(format!(
                    "joints.{name}: needs vertices of the base mesh (below {vertex_count})"
                )));
            }
            joint_index.insert(name.clone(), joints.len());
            joints.push((name, vertices));
        }
        let joint = |bone: &str, field: &str, name: &str| {
            joint_index
                .get(name)
                .copied()
                .ok_or_else(|| bad(format!("bones.{bone}.{field}: no joint `{name}`")))
        };
        // Parents first: repeatedly take the bones whose parent is placed (BTreeMap: by name).
        let mut bones: Vec<Bone> = Vec::new();
        let mut placed: HashMap<&str, usize> = HashMap::new();
        while bones.len() < parsed.bones.len() {
            let before = bones.len();
            for (name, b) in &parsed.bones {
                if placed.contains_key(name.as_str()) {
                    continue;
                }
                let parent = match &b.parent {
                    None => None,
                    Some(p) if !parsed.bones.contains_key(p) => {
                        return Err(bad(format!("bones.{name}.parent: no bone `{p}`")));
                    }
                    Some(p) => match placed.get(p.as_str()) {
                        Some(&i) => Some(i),
                        None => continue,
                    },
                };
                placed.insert(name, bones.len());
                bones.push(Bone {
                    name: name.clone(),
                    parent,
                    head: joint(name, "head", &b.head)?,
                    tail: joint(name, "tail", &b.tail)?,
                });
            }
            if bones.len() == before {
                return Err(bad("bones: the parents form a cycle".into()));
            }
        }
        Ok(Rig { bones, joints })
    }

    /// The index of the bone called `name`.
    pub fn bone(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Every joint's position for a full vertex list: the mean of its listed vertices.
    pub fn joint_positions(&self, vertices: &[DVec3]) -> Vec<DVec3> {
        self.joints
            .iter()
            .map(|(_, list)| {
                list.iter().map(|&v| vertices[v as usize]).sum::<DVec3>() / list.len() as f64
            })
            .collect()
    }

    /// Each bone's head joint (the point it rotates about) for a full vertex list.
    pub fn bone_heads(&self, vertices: &[DVec3]) -> Vec<DVec3> {
        let joints = self.joint_positions(vertices);
        self.bones.iter().map(|b| joints[b.head]).collect()
    }

    /// The parent of each bone, in bone order.
    pub fn parents(&self) -> Vec<Option<usize>> {
        self.bones.iter().map(|b| b.parent).collect()
    }
}
