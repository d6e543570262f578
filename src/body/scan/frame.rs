//! The canonical body frame: millimetres, Z up, floor at z = 0, +X = the subject's left, the
//! subject facing -Y (right-handed, as in Blender's front view), origin under the torso's
//! centre: the bounding-box centre of the largest horizontal section at 58% of the height
//! (the waist, which no arm pose moves). Scans arrive in any unit, with Y or Z up and turned any way about the vertical; this
//! module finds out which, and keeps the transform so outputs can go back to the scan's frame.
//!
//! Detection, each step overridable:
//! - **up**: the axis of the largest extent (a standing body is taller than wide or deep); its
//!   sign from the area-weighted centroid, which sits above mid-height (torso, arms and head
//!   carry more surface than the legs);
//! - **units**: from the height — a standing person is 0.5-2.5 m tall, and that range in m,
//!   dm, cm and mm does not overlap; inches overlap centimetres (a 1.2-2.2 m adult is 47-87
//!   inches, which in centimetres would be a toddler) and decimetres, so where several units
//!   make a person, the first (m, dm, cm, mm, in) that makes the body at least 1 m tall
//!   ([`SMALLEST_CUSTOMER_MM`]) is taken, and the reading is named in a warning
//!   ([`CanonicalFrame::units_warning`]). Its limit: a scan in centimetres of a child under
//!   1 m (50-98 units tall) is read as inches, one in inches of a body under 0.64 m as
//!   decimetres; `--units` overrides;
//! - **left-right axis**: the major principal axis of the surface between hips and shoulders
//!   (shoulders, hips and hanging arms are wider than the body is deep); exact for a
//!   mirror-symmetric body, whatever its turn;
//! - **front**: the side the feet point to (the lowest 4% of the body lies in front of the
//!   shins).

use crate::body::mesh::{Aabb, Mesh};
use crate::body::slice::sections;
use glam::{DMat3, DVec2, DVec3};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The heights a standing person can have (mm): from a small child to the tallest adults,
/// with margin; the ranges in m, dm, cm and mm do not overlap, so the height tells the unit.
pub const PERSON_HEIGHT_MM: (f64, f64) = (500.0, 2500.0);

/// The smallest stature of a customer a dress form is made for (mm): about a four-year-old
/// (the WHO Child Growth Standards' median at 4 years is 102-103 cm). Where a scan's height
/// makes a person in several units, the first unit that makes it at least this tall is taken.
pub const SMALLEST_CUSTOMER_MM: f64 = 1000.0;

/// The statures of usual customers (mm): from [`SMALLEST_CUSTOMER_MM`] to 2.2 m (above the
/// 99.99th percentile of adult stature in national surveys). A scan whose detected units
/// make it another height and that cannot be reconstructed gets a hint naming the units.
pub const USUAL_STATURE_MM: (f64, f64) = (SMALLEST_CUSTOMER_MM, 2200.0);

/// Millimetres in an inch (international yard and pound agreement, 1959).
pub const MM_PER_INCH: f64 = 25.4;

/// A length unit a scan may be stored in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// Metres.
    M,
    /// Decimetres (MakeHuman).
    Dm,
    /// Centimetres.
    Cm,
    /// Millimetres.
    Mm,
    /// Inches (scanners sold in the US).
    In,
}

impl Units {
    /// Every unit: the metric ones largest first, then inches (the order in which detection
    /// prefers them).
    pub const ALL: [Units; 5] = [Units::M, Units::Dm, Units::Cm, Units::Mm, Units::In];

    /// The unit's symbol: `m`, `dm`, `cm`, `mm` or `in` (as files, JSON and the command line
    /// spell it).
    pub fn symbol(self) -> &'static str {
        match self {
            Units::M => "m",
            Units::Dm => "dm",
            Units::Cm => "cm",
            Units::Mm => "mm",
            Units::In => "in",
        }
    }

    /// Millimetres in one unit.
    pub fn mm(self) -> f64 {
        match self {
            Units::M => 1000.0,
            Units::Dm => 100.0,
            Units::Cm => 10.0,
            Units::Mm => 1.0,
            Units::In => MM_PER_INCH,
        }
    }

    /// The units in which `height` is the height of a standing person (0.5-2.5 m), in the
    /// order of [`Units::ALL`].
    pub fn candidates(height: f64) -> impl Iterator<Item = Units> {
        Units::ALL
            .into_iter()
            .filter(move |u| (PERSON_HEIGHT_MM.0..=PERSON_HEIGHT_MM.1).contains(&(height * u.mm())))
    }

    /// The unit of a scan `height` units tall: of the units that make it a standing person,
    /// the first that makes it at least [`SMALLEST_CUSTOMER_MM`] tall, else the first.
    pub fn from_height(height: f64) -> Option<Units> {
        let customer = |u: &Units| height * u.mm() >= SMALLEST_CUSTOMER_MM;
        Units::candidates(height).find(customer).or_else(|| Units::candidates(height).next())
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// A signed coordinate axis of the scan's frame: `+x`, `-y`, `z` (= `+z`), ...
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Direction {
    axis: usize,
    negative: bool,
}

impl Direction {
    /// The unit vector.
    pub fn vector(self) -> DVec3 {
        let mut v = DVec3::ZERO;
        v[self.axis] = if self.negative { -1.0 } else { 1.0 };
        v
    }

    /// The signed axis that `v` points along, if it is within 1 degree of one.
    pub fn nearest(v: DVec3) -> Option<Direction> {
        let axis = v.abs().max_position();
        let d = Direction { axis, negative: v[axis] < 0.0 };
        (d.vector().dot(v.normalize_or_zero()) > 1.0f64.to_radians().cos()).then_some(d)
    }
}

impl FromStr for Direction {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let lower = s.to_ascii_lowercase();
        let (negative, name) = match lower.as_bytes() {
            [b'-', rest @ ..] => (true, rest),
            [b'+', rest @ ..] => (false, rest),
            rest => (false, rest),
        };
        let axis = match name {
            b"x" => 0,
            b"y" => 1,
            b"z" => 2,
            _ => return Err(format!("'{s}' is not an axis: use x, y, z, -x, -y or -z")),
        };
        Ok(Direction { axis, negative })
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", if self.negative { '-' } else { '+' }, ["x", "y", "z"][self.axis])
    }
}

impl Serialize for Direction {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// What the user says about the scan's frame; `None` means "detect it".
#[derive(Debug, Clone, Copy, Default)]
pub struct FrameOptions {
    /// The scan's length unit.
    pub units: Option<Units>,
    /// The scan's up direction.
    pub up: Option<Direction>,
    /// The direction the subject faces, in the scan's frame.
    pub facing: Option<Direction>,
}

/// Why the canonical frame could not be established.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// The height matches no unit for a person.
    #[error(
        "the body is {} units tall along {up}, which is 0.5-2.5 m in none of m, dm, cm, mm, in; \
         pass --units (and check --up)", crate::messages::number(*height)
    )]
    UnknownUnits {
        /// Height in the file's units.
        height: f64,
        /// The up direction used.
        up: Direction,
    },
    /// `--units` makes the body a height no standing person has.
    #[error(
        "with --units {units} the body is {} mm tall, and a standing person is 500-2500 mm; \
         {hint}", crate::messages::number(height_mm.round())
    )]
    ImplausibleUnits {
        /// The unit given.
        units: Units,
        /// The height it gives (mm).
        height_mm: f64,
        /// What to do instead.
        hint: String,
    },
    /// `--up` puts the head below the feet, or makes the body wider than tall.
    #[error("with --up {up} {problem}; {hint}")]
    ImplausibleUp {
        /// The up direction given.
        up: Direction,
        /// What no standing person looks like.
        problem: String,
        /// What to do instead.
        hint: String,
    },
    /// `--facing` along the up axis.
    #[error("--facing {facing} is not horizontal when up is {up}")]
    FacingNotHorizontal {
        /// The facing given.
        facing: Direction,
        /// The up direction used.
        up: Direction,
    },
}

/// How a scan's coordinates map to the canonical frame: `canonical = R (s p) + t`.
#[derive(Debug, Clone, Serialize)]
pub struct CanonicalFrame {
    /// The scan's unit.
    pub units: Units,
    /// Whether `units` was detected (rather than given).
    pub units_detected: bool,
    /// The scan's up direction.
    pub up: Direction,
    /// Whether `up` was detected.
    pub up_detected: bool,
    /// The direction the subject faces, in the scan's frame (a unit vector).
    pub facing: DVec3,
    /// Whether `facing` was detected.
    pub facing_detected: bool,
    /// How far (mm) the feet lie in front of the shins: the evidence for the facing.
    /// Near zero means the front could not be told from the back.
    pub facing_evidence_mm: f64,
    /// Height of the body in mm.
    pub height_mm: f64,
    /// Whether the frame was stated in the file's header (a file dressform wrote, see
    /// [`FileFrame`]) rather than detected or given.
    pub from_header: bool,
    #[serde(skip)]
    rotation: DMat3,
    #[serde(skip)]
    translation: DVec3,
}

impl CanonicalFrame {
    /// A scan point in the canonical frame.
    pub fn to_canonical(&self, p: DVec3) -> DVec3 {
        self.rotation * (p * self.units.mm()) + self.translation
    }

    /// A canonical point back in the scan's frame.
    pub fn to_scan(&self, q: DVec3) -> DVec3 {
        self.rotation.transpose() * (q - self.translation) / self.units.mm()
    }

    /// Moves the origin under the torso of `body` (already in this frame): the bounding-box
    /// centre of its largest section at 58% of the height. Updates `body` and the transform.
    pub fn centre_on_torso(&mut self, body: &mut Mesh) {
        let z = 0.58 * self.height_mm;
        let Some(torso) =
            sections(body, &[z]).into_iter().next().and_then(|s| s.loops.into_iter().next())
        else {
            return;
        };
        let Some(b) = Aabb::around(torso.points.iter().map(|p| p.extend(0.0))) else { return };
        let shift = DVec3::new(0.5 * (b.min.x + b.max.x), 0.5 * (b.min.y + b.max.y), 0.0);
        self.translate(body, -shift);
    }

    /// Moves `body` (already in this frame) by `offset` (mm) and records the move in the
    /// transform, so that the body still maps back to where the scan stood.
    pub fn translate(&mut self, body: &mut Mesh, offset: DVec3) {
        body.transform(|p| p + offset);
        self.translation += offset;
    }

    /// The map from the scan's coordinates to this frame, as a header states it.
    pub fn file_frame(&self) -> FileFrame {
        FileFrame {
            units: self.units,
            rotation: self.rotation.transpose().to_cols_array_2d(),
            translation: self.translation.to_array(),
        }
    }

    /// The frame a file's header states (see [`FileFrame`]), for `mesh` in the file's
    /// coordinates: no detection, no centring, the floor where the header puts it.
    pub fn stated(file: &FileFrame, mesh: &Mesh) -> Result<CanonicalFrame, String> {
        let rotation = DMat3::from_cols_array_2d(&file.rotation).transpose();
        let orthonormal = (rotation * rotation.transpose() - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|e| e.abs() <= ROTATION_TOLERANCE);
        if !orthonormal || (rotation.determinant() - 1.0).abs() > ROTATION_TOLERANCE {
            return Err("rotation: not a rotation matrix".to_string());
        }
        let translation = DVec3::from_array(file.translation);
        if !translation.is_finite() {
            return Err("translation_mm: not finite".to_string());
        }
        let up = Direction::nearest(rotation.transpose() * DVec3::Z)
            .ok_or("rotation: the up direction is not an axis of the file")?;
        let mut frame = CanonicalFrame {
            units: file.units,
            units_detected: false,
            up,
            up_detected: false,
            facing: rotation.transpose() * DVec3::NEG_Y,
            facing_detected: false,
            facing_evidence_mm: 0.0,
            height_mm: 0.0,
            from_header: true,
            rotation,
            translation,
        };
        let top = mesh.positions.iter().map(|&p| frame.to_canonical(p).z).fold(0.0, f64::max);
        frame.height_mm = top;
        Ok(frame)
    }

    /// When the units were detected and another unit would also have made a standing person
    /// (inches against centimetres or decimetres): which reading was taken, the other, and
    /// how to choose it.
    pub fn units_warning(&self) -> Option<String> {
        if !self.units_detected {
            return None;
        }
        let height = self.height_mm / self.units.mm();
        let other = Units::candidates(height).find(|&u| u != self.units)?;
        Some(format!(
            "units: read as {} ({} mm tall); in {other} the body would be {} mm tall: pass \
             --units {other} if that is right",
            self.units,
            crate::messages::number(self.height_mm.round()),
            crate::messages::number((height * other.mm()).round()),
        ))
    }

    /// For a message about a scan that could not be reconstructed: when the units were
    /// detected and the body's size is unusual for a customer ([`USUAL_STATURE_MM`]) or
    /// another unit would also make a person, the units assumed and how to override them.
    pub fn units_hint(&self) -> Option<String> {
        let usual = (USUAL_STATURE_MM.0..=USUAL_STATURE_MM.1).contains(&self.height_mm);
        if !self.units_detected || (usual && self.units_warning().is_none()) {
            return None;
        }
        Some(format!(
            "read as {}, detected: {} mm tall; if wrong, pass --units",
            self.units,
            crate::messages::number(self.height_mm.round()),
        ))
    }

    /// `facing` as an axis name when it is one (within 1 degree).
    pub fn facing_axis(&self) -> Option<Direction> {
        Direction::nearest(self.facing)
    }
}

/// How a file's coordinates map to the canonical frame, as the header of a file dressform
/// wrote states it: `canonical = rotation (p units) + translation`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FileFrame {
    /// The file's unit.
    pub units: Units,
    /// The rotation, row by row.
    pub rotation: [[f64; 3]; 3],
    /// The translation (mm).
    #[serde(rename = "translation_mm")]
    pub translation: [f64; 3],
}

/// How far a stated rotation may be from orthonormal: a header writes its entries to about
/// 17 significant digits, so only a corrupted one comes near this.
const ROTATION_TOLERANCE: f64 = 1e-6;

/// Area-weighted sums over triangle centroids: weight, first moment, and the second moments
/// of two horizontal coordinates.
#[derive(Debug, Clone, Copy, Default)]
struct Moments {
    weight: f64,
    sum: DVec3,
    xx: f64,
    xy: f64,
    yy: f64,
}

impl Moments {
    /// A triangle's own moments (centroid `p`, area `a`, horizontal coordinates `flat`).
    fn of(p: DVec3, a: f64, flat: DVec2) -> Moments {
        Moments {
            weight: a,
            sum: p * a,
            xx: a * flat.x * flat.x,
            xy: a * flat.x * flat.y,
            yy: a * flat.y * flat.y,
        }
    }

    fn merge(mut self, o: Moments) -> Moments {
        self.weight += o.weight;
        self.sum += o.sum;
        self.xx += o.xx;
        self.xy += o.xy;
        self.yy += o.yy;
        self
    }

    fn mean(&self) -> Option<DVec3> {
        (self.weight > 0.0).then(|| self.sum / self.weight)
    }
}

/// Sums `add(sums, centroid, area)` over the triangles of `mesh` block by block (in
/// parallel), in block order: with [`merged`], the same bits on every run (see
/// [`crate::body::mesh::reduce`]).
fn block_sums<T: Default + Send>(mesh: &Mesh, add: impl Fn(&mut T, DVec3, f64) + Sync) -> Vec<T> {
    // Each block adds into one accumulator in place (a fold that passes it by value copies
    // the moments for every triangle).
    crate::body::mesh::reduce::blocks(mesh.triangles.len(), |range| {
        let mut m = T::default();
        for t in range {
            let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
            add(&mut m, (a + b + c) / 3.0, 0.5 * (b - a).cross(c - a).length());
        }
        m
    })
}

/// The blocks' moments of [`block_sums`] (or of a pass like it), merged in block order.
fn merged<const N: usize>(blocks: Vec<[Moments; N]>) -> [Moments; N] {
    let merge = |x: [Moments; N], y: [Moments; N]| std::array::from_fn(|k| x[k].merge(y[k]));
    blocks.into_iter().fold([Moments::default(); N], merge)
}

/// What detecting the frame needs of a body's surface, gathered in one pass over its
/// triangles: its bounding box, the area-weighted centroid, and the moments of the trunk,
/// feet and shins bands along its longest axis either way up (which way is up is only known
/// from the centroid). See [`Survey::of`], or [`Surveyor`] to gather it in a pass over the
/// triangles that another step makes anyway (the cleaning's: see
/// [`super::clean::clean_surveyed`]).
#[derive(Debug, Clone)]
pub struct Survey {
    bounds: Aabb,
    /// Every triangle, then the longest axis's bands pointing up, then pointing down.
    moments: [Moments; 7],
}

impl Survey {
    /// The survey of `mesh`: a pass over its vertices for the box, one over its triangles.
    pub fn of(mesh: &Mesh) -> Survey {
        let surveyor = Surveyor::new(mesh);
        let blocks = block_sums(mesh, |m: &mut SurveyBlock, p, a| surveyor.add(m, p, a));
        surveyor.finish(blocks)
    }
}

/// Gathers a [`Survey`] of a mesh block by block: [`Self::add`] each triangle (centroid and
/// area, as [`block_sums`] computes them) of each block of [`crate::body::mesh::reduce::BLOCK`]
/// triangles in order, then [`Self::finish`] with the blocks in order; the same bits as
/// [`Survey::of`].
pub struct Surveyor {
    bounds: Aabb,
    up: Bands,
    down: Bands,
}

/// One block's share of a [`Survey`] ([`Surveyor`]): the moments of every triangle, then of
/// the bands pointing up, then pointing down.
#[derive(Debug, Clone, Copy, Default)]
pub struct SurveyBlock([Moments; 7]);

impl Surveyor {
    /// A surveyor of `mesh`: its bounding box and the bands along its longest axis.
    pub fn new(mesh: &Mesh) -> Surveyor {
        let bounds = mesh.bounds().unwrap_or(Aabb { min: DVec3::ZERO, max: DVec3::ZERO });
        let axis = bounds.size().max_position();
        let along = |negative: bool| Bands::new(Direction { axis, negative }, &bounds);
        Surveyor { bounds, up: along(false), down: along(true) }
    }

    /// Adds a triangle (centroid `p`, area `a`) to `block`: to every triangle's moments, and
    /// to its band either way up (its own moments computed once for both).
    pub fn add(&self, block: &mut SurveyBlock, p: DVec3, a: f64) {
        let m = &mut block.0;
        // Of every triangle's moments only the centroid is used.
        m[0].weight += a;
        m[0].sum += p * a;
        let along = p[self.up.axis];
        let bands = [self.up.band(along).map(|k| 1 + k), self.down.band(along).map(|k| 4 + k)];
        if bands.iter().any(Option::is_some) {
            let own = Moments::of(p, a, self.up.flat(p));
            for k in bands.into_iter().flatten() {
                m[k] = m[k].merge(own);
            }
        }
    }

    /// The survey from the blocks' shares, in block order.
    pub fn finish(self, blocks: Vec<SurveyBlock>) -> Survey {
        Survey { bounds: self.bounds, moments: merged(blocks.into_iter().map(|b| b.0).collect()) }
    }
}

/// The trunk's band, by fraction of the height from the floor: hips to shoulders.
const TRUNK_BAND: (f64, f64) = (0.45, 0.75);
/// The feet's band: up to this fraction of the height.
const FEET_BAND_TOP: f64 = 0.04;
/// The shins' band, by fraction of the height.
const SHIN_BAND: (f64, f64) = (0.10, 0.25);

/// The surface's bands along an up direction, by fraction of the height: trunk (hips to
/// shoulders), feet, shins; horizontal coordinates on the two other axes.
struct Bands {
    /// The up direction's axis, and +1 or -1 along it.
    axis: usize,
    sign: f64,
    floor: f64,
    height: f64,
    e1: DVec3,
    e2: DVec3,
    /// The bands' limits along the up direction (`floor + fraction * height`), so that a
    /// triangle's band takes comparisons only, no division, in the pass over every triangle.
    trunk: (f64, f64),
    feet_top: f64,
    shins: (f64, f64),
}

impl Bands {
    fn new(up: Direction, bounds: &Aabb) -> Bands {
        let u = up.vector();
        let (floor, top) =
            (bounds.min.dot(u).min(bounds.max.dot(u)), bounds.min.dot(u).max(bounds.max.dot(u)));
        let height = top - floor;
        let at = |fraction: f64| floor + fraction * height;
        let e1 = Direction { axis: (up.axis + 1) % 3, negative: false }.vector();
        let e2 = Direction { axis: (up.axis + 2) % 3, negative: false }.vector();
        Bands {
            axis: up.axis,
            sign: if up.negative { -1.0 } else { 1.0 },
            floor,
            height,
            e1,
            e2,
            trunk: (at(TRUNK_BAND.0), at(TRUNK_BAND.1)),
            feet_top: at(FEET_BAND_TOP),
            shins: (at(SHIN_BAND.0), at(SHIN_BAND.1)),
        }
    }

    /// Horizontal coordinates of `p` (its coordinates on the axes `e1` and `e2`).
    fn flat(&self, p: DVec3) -> DVec2 {
        DVec2::new(p[(self.axis + 1) % 3], p[(self.axis + 2) % 3])
    }

    /// The band of a point whose coordinate along the up direction's axis is `along`: 0 for
    /// the trunk, 1 the feet, 2 the shins; `None` outside them.
    fn band(&self, along: f64) -> Option<usize> {
        let s = self.sign * along;
        match s {
            _ if (self.trunk.0..=self.trunk.1).contains(&s) => Some(0),
            _ if s <= self.feet_top => Some(1),
            _ if (self.shins.0..=self.shins.1).contains(&s) => Some(2),
            _ => None,
        }
    }

    /// Adds a triangle (centroid `p`, area `a`) to the moments of its band: `m` holds trunk,
    /// feet, shins.
    fn add(&self, m: &mut [Moments], p: DVec3, a: f64) {
        if let Some(k) = self.band(p[self.axis]) {
            m[k] = m[k].merge(Moments::of(p, a, self.flat(p)));
        }
    }
}

/// The smallest ratio of height to the largest horizontal extent of a standing person: arms
/// spread horizontally span about the stature (arm span / stature is 0.95-1.06 in adults),
/// so a body wider than 1.25 times its height is lying down or seen along the wrong axis.
const MIN_HEIGHT_TO_WIDTH: f64 = 0.8;

/// Checks that `up` (given by the user) shows a standing person: the surface's centroid above
/// mid-height (torso, arms and head carry more surface than the legs) and the body no wider
/// than a person with spread arms. `detected` is what detection would have chosen.
fn check_up(
    up: Direction,
    bounds: &Aabb,
    centroid: DVec3,
    detected: Direction,
) -> Result<(), FrameError> {
    let hint = if detected == up {
        "check that the file holds one standing person".to_string()
    } else {
        format!("the body stands along {detected}: pass --up {detected} or leave --up out")
    };
    let axis = up.axis;
    let height = bounds.size()[axis];
    let width = (0..3).filter(|&a| a != axis).map(|a| bounds.size()[a]).fold(0.0, f64::max);
    let mid = 0.5 * (bounds.min[axis] + bounds.max[axis]);
    let problem = if (centroid[axis] < mid) != up.negative {
        "the head is below the feet (the surface's centroid is below mid-height)".to_string()
    } else if height < MIN_HEIGHT_TO_WIDTH * width {
        format!(
            "the body is {:.0}% as tall as it is wide, and a standing person is at least {:.0}%",
            100.0 * height / width,
            100.0 * MIN_HEIGHT_TO_WIDTH
        )
    } else {
        return Ok(());
    };
    Err(FrameError::ImplausibleUp { up, problem, hint })
}

/// Finds the canonical frame of `mesh` (a cleaned body), honouring `options`; a given unit or
/// up axis that makes no standing person is refused with the likely fix.
pub fn detect(mesh: &Mesh, options: &FrameOptions) -> Result<CanonicalFrame, FrameError> {
    detect_surveyed(mesh, Survey::of(mesh), options)
}

/// [`detect`] with the [`Survey`] of `mesh` already taken (it must be `mesh`'s: see
/// [`Surveyor`]); a stated up along another axis than the longest takes a pass for its bands.
pub fn detect_surveyed(
    mesh: &Mesh,
    survey: Survey,
    options: &FrameOptions,
) -> Result<CanonicalFrame, FrameError> {
    let Survey { bounds, moments: [all, rest @ ..] } = survey;
    let axis = bounds.size().max_position();
    let centroid = all.mean().unwrap_or(bounds.min);
    let detected_up =
        Direction { axis, negative: centroid[axis] < 0.5 * (bounds.min[axis] + bounds.max[axis]) };
    let up = match options.up {
        Some(up) => {
            check_up(up, &bounds, centroid, detected_up)?;
            up
        }
        None => detected_up,
    };
    let bands = Bands::new(up, &bounds);
    let (u, floor, height) = (up.vector(), bands.floor, bands.height);
    let units = match options.units {
        Some(units) => {
            let height_mm = height * units.mm();
            if !(PERSON_HEIGHT_MM.0..=PERSON_HEIGHT_MM.1).contains(&height_mm) {
                let hint = match Units::from_height(height) {
                    Some(fit) => format!(
                        "the file looks like {fit}: pass --units {fit} or leave --units out"
                    ),
                    None => {
                        format!("no unit makes it a person along {up}: check --up and the file")
                    }
                };
                return Err(FrameError::ImplausibleUnits { units, height_mm, hint });
            }
            units
        }
        None => Units::from_height(height).ok_or(FrameError::UnknownUnits { height, up })?,
    };

    let [trunk, feet, shins] = match (up.axis == axis, up.negative) {
        (true, false) => [rest[0], rest[1], rest[2]],
        (true, true) => [rest[3], rest[4], rest[5]],
        (false, _) => merged(block_sums(mesh, |m: &mut [Moments; 3], p, a| bands.add(m, p, a))),
    };
    let flat = |p: DVec3| bands.flat(p);
    let centre = trunk.mean().unwrap_or(bounds.min);
    let c2 = flat(centre);
    let w = trunk.weight.max(f64::MIN_POSITIVE);
    let (sxx, sxy, syy) =
        (trunk.xx / w - c2.x * c2.x, trunk.xy / w - c2.x * c2.y, trunk.yy / w - c2.y * c2.y);
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let front_back = DVec2::new(-theta.sin(), theta.cos());
    let evidence = match (feet.mean(), shins.mean()) {
        (Some(f), Some(s)) => (flat(f) - flat(s)).dot(front_back),
        _ => 0.0,
    };
    let (facing, facing_detected) = match options.facing {
        Some(f) => {
            if f.axis == up.axis {
                return Err(FrameError::FacingNotHorizontal { facing: f, up });
            }
            (f.vector(), false)
        }
        None => {
            let forward = if evidence >= 0.0 { front_back } else { -front_back };
            ((bands.e1 * forward.x + bands.e2 * forward.y).normalize(), true)
        }
    };
    let left = u.cross(facing);
    let rotation = DMat3::from_cols(left, -facing, u).transpose();
    let scale = units.mm();
    let c = rotation * (centre * scale);
    let translation = DVec3::new(-c.x, -c.y, -floor * scale);
    Ok(CanonicalFrame {
        units,
        units_detected: options.units.is_none(),
        up,
        up_detected: options.up.is_none(),
        facing,
        facing_detected,
        facing_evidence_mm: evidence.abs() * scale,
        height_mm: height * scale,
        from_header: false,
        rotation,
        translation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inches_are_read_where_centimetres_would_make_a_toddler() {
        // A 1.70 m adult in each unit.
        for unit in Units::ALL {
            assert_eq!(Units::from_height(1700.0 / unit.mm()), Some(unit), "{unit}");
        }
        // 1.2-2.2 m adults in inches (47-87 units) are not centimetres.
        for inches in [47.3, 60.0, 87.0] {
            assert_eq!(Units::from_height(inches), Some(Units::In), "{inches}");
        }
        // The limit, as documented: a child under 1 m in centimetres reads as inches...
        assert_eq!(Units::from_height(80.0), Some(Units::In));
        // ... but not one of 1 m or more, nor where inches would be over 2.5 m.
        assert_eq!(Units::from_height(110.0), Some(Units::Cm));
        assert_eq!(Units::from_height(99.0), Some(Units::Cm));
        // An inch scan of a child under 0.64 m reads as decimetres.
        assert_eq!(Units::from_height(22.0), Some(Units::Dm));
        // Where no unit makes a usual customer, the first that makes a person.
        assert_eq!(Units::from_height(0.6), Some(Units::M));
        assert_eq!(Units::from_height(3.0), None);
    }
}
