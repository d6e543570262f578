//! The segmented body: a body (canonical frame, mm) with its regions and landmarks, segmented
//! once, and the one way every later stage gets the body's sections. `measure`, `mannequin`,
//! `measure::compare` and the pipeline's girth table take a [`SegmentedBody`]; none of them
//! segments the mesh again.
//!
//! The torso's sections (labelled, and clipped at the armholes: [`BodyRegions::torso_of`]) are
//! cached by height: the measurement rules, the mannequin's layers, the comparison and the
//! dimensions ask for the chest, waist and hip levels again and again. A section depends only
//! on its own height ([`sections`] cuts each plane on its own), so a cached loop is the one a
//! new cut would give.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

use crate::body::mesh::Mesh;
use crate::body::regions::{
    BodyRegions, Landmarks, Region, RegionError, TRACKING_STEP_MM, largest_with,
};
use crate::body::slice::{Contour, Section, sections};

/// A body with its regions and landmarks, and its sections on request.
#[derive(Debug)]
pub struct SegmentedBody<'a> {
    mesh: &'a Mesh,
    regions: Cow<'a, BodyRegions>,
    /// The torso's section at each height asked for so far, by the height's bits.
    torso: Mutex<HashMap<u64, Option<Contour>>>,
}

impl<'a> SegmentedBody<'a> {
    /// Segments `mesh` (canonical frame), tracking its loops every [`TRACKING_STEP_MM`].
    pub fn find(mesh: &'a Mesh) -> Result<SegmentedBody<'a>, RegionError> {
        Ok(Self::owning(mesh, BodyRegions::find(mesh, TRACKING_STEP_MM)?))
    }

    /// A body without arms and head whose `landmarks` are known (a mannequin dressform made,
    /// whose file carries them): see [`BodyRegions::armless`].
    pub fn armless(mesh: &'a Mesh, landmarks: Landmarks) -> SegmentedBody<'a> {
        Self::owning(mesh, BodyRegions::armless(landmarks))
    }

    /// `mesh` labelled by `regions` found before (on this mesh, or on the body a mesh in the
    /// same frame was made from, as the preview draws the mannequin's loops).
    pub fn with_regions(mesh: &'a Mesh, regions: &'a BodyRegions) -> SegmentedBody<'a> {
        SegmentedBody { mesh, regions: Cow::Borrowed(regions), torso: Mutex::default() }
    }

    fn owning(mesh: &'a Mesh, regions: BodyRegions) -> SegmentedBody<'a> {
        SegmentedBody { mesh, regions: Cow::Owned(regions), torso: Mutex::default() }
    }

    /// The body's mesh.
    pub fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// The body's regions.
    pub fn regions(&self) -> &BodyRegions {
        &self.regions
    }

    /// The body's landmarks.
    pub fn landmarks(&self) -> &Landmarks {
        &self.regions.landmarks
    }

    /// The regions, for a value that outlives the mesh's borrow.
    pub fn into_regions(self) -> BodyRegions {
        self.regions.into_owned()
    }

    /// The body's sections at `heights`, unlabelled (label them with [`BodyRegions::label`]).
    pub fn sections(&self, heights: &[f64]) -> Vec<Section> {
        sections(self.mesh, heights)
    }

    /// The torso's section at each of `heights` (`None` where there is none), as
    /// [`BodyRegions::torso_of`] picks it; cut once per height.
    pub fn torso_sections(&self, heights: &[f64]) -> Vec<Option<Contour>> {
        let missing: Vec<f64> = {
            let torso = self.torso.lock().unwrap_or_else(PoisonError::into_inner);
            heights.iter().copied().filter(|z| !torso.contains_key(&z.to_bits())).collect()
        };
        let found: Vec<(u64, Option<Contour>)> = sections(self.mesh, &missing)
            .iter()
            .map(|s| (s.height.to_bits(), self.regions.torso_of(s)))
            .collect();
        let mut torso = self.torso.lock().unwrap_or_else(PoisonError::into_inner);
        torso.extend(found);
        heights.iter().map(|z| torso.get(&z.to_bits()).cloned().flatten()).collect()
    }

    /// The section of `region` at each of `heights`: the torso's as [`Self::torso_sections`],
    /// another region's as its largest loop.
    pub fn sections_of(&self, region: Region, heights: &[f64]) -> Vec<Option<Contour>> {
        if region == Region::Torso {
            return self.torso_sections(heights);
        }
        sections(self.mesh, heights)
            .into_iter()
            .map(|s| largest_with(&s, &self.regions.label(&s), region).cloned())
            .collect()
    }
}
