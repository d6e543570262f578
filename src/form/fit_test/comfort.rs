//! How a contact pressure is judged: comfort bands for daily wear, and the compression classes
//! of RAL-GZ 387 for compression garments.
//!
//! **Daily wear** (the bands of issue 30; the clothing-pressure literature puts discomfort in
//! the few-kPa range, e.g. waistbands over about 35 mmHg, 4.7 kPa, drew complaints in Sen'i
//! Gakkaishi 47(6):282): below [`LOOSE_BELOW_KPA`] loose or negligible, up to
//! [`COMFORT_LIMIT_KPA`] comfortable, up to [`TIGHT_ABOVE_KPA`] critical, above it too tight.
//!
//! **Compression** (RAL-GZ 387/1, medical compression hosiery, pressure at the ankle):
//! class I 18-21 mmHg, II 23-32, III 34-46, IV 49 and over; a pressure between two classes is
//! reported as such. (CEN's ENV 12718 starts class I at 15 mmHg; RAL's is the German quality
//! mark the issue names.)

use serde::Serialize;

/// Below this the garment is loose or its pressure negligible, kPa.
pub const LOOSE_BELOW_KPA: f64 = 0.4;
/// Above this daily wear is no longer comfortable, kPa: where a sweep says a garment binds.
pub const COMFORT_LIMIT_KPA: f64 = 1.3;
/// Above this daily wear is too tight, kPa.
pub const TIGHT_ABOVE_KPA: f64 = 2.0;

/// kPa per mmHg (133.322 Pa).
pub const KPA_PER_MMHG: f64 = 0.133_322;

/// RAL-GZ 387's compression classes, mmHg: lower and upper bounds (class IV has none).
const RAL_CLASSES_MMHG: [(f64, f64); 4] =
    [(18.0, 21.0), (23.0, 32.0), (34.0, 46.0), (49.0, f64::INFINITY)];

/// Where a compression garment reaches class I, kPa: what a sweep looks for on one.
pub const CLASS_I_FROM_KPA: f64 = RAL_CLASSES_MMHG[0].0 * KPA_PER_MMHG;

/// A ring's verdict; in JSON the kebab-case of its words (`too-tight`, `class-ii`,
/// `between-class-i-and-ii`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Some panel of the ring has no force reading: nothing can be said.
    NotMeasured,
    /// The garment does not touch the ring.
    NoContact,
    /// Daily wear: loose, pressure negligible.
    Loose,
    /// Daily wear: comfortable.
    Comfortable,
    /// Daily wear: critical, near discomfort.
    Critical,
    /// Daily wear: too tight.
    TooTight,
    /// Compression: below class I.
    BelowClassI,
    /// Compression: in RAL-GZ 387 class I..=IV (the number).
    Class(u8),
    /// Compression: between two classes (the lower's number).
    AboveClass(u8),
}

impl Verdict {
    /// Daily wear judged by its mean pressure (kPa); `contact` false: no contact.
    pub fn daily(pressure_kpa: f64, contact: bool) -> Self {
        match pressure_kpa {
            _ if !contact => Self::NoContact,
            p if p < LOOSE_BELOW_KPA => Self::Loose,
            p if p <= COMFORT_LIMIT_KPA => Self::Comfortable,
            p if p <= TIGHT_ABOVE_KPA => Self::Critical,
            _ => Self::TooTight,
        }
    }

    /// A compression garment judged by its mean pressure (kPa).
    pub fn compression(pressure_kpa: f64, contact: bool) -> Self {
        if !contact {
            return Self::NoContact;
        }
        let mmhg = pressure_kpa / KPA_PER_MMHG;
        let mut verdict = Self::BelowClassI;
        for (k, (lo, hi)) in RAL_CLASSES_MMHG.iter().enumerate() {
            let class = k as u8 + 1;
            if mmhg >= *lo && mmhg <= *hi {
                return Self::Class(class);
            }
            if mmhg > *hi {
                verdict = Self::AboveClass(class);
            }
        }
        verdict
    }

    /// Whether the ring is flagged: daily wear critical or too tight.
    pub fn flagged(self) -> bool {
        matches!(self, Self::Critical | Self::TooTight)
    }

    /// In words, for tables.
    pub fn words(self) -> String {
        let roman =
            |c: u8| ["I", "II", "III", "IV"].get(usize::from(c) - 1).copied().unwrap_or("?");
        match self {
            Self::NotMeasured => "not measured".into(),
            Self::NoContact => "no contact".into(),
            Self::Loose => "loose".into(),
            Self::Comfortable => "comfortable".into(),
            Self::Critical => "CRITICAL".into(),
            Self::TooTight => "TOO TIGHT".into(),
            Self::BelowClassI => "below class I".into(),
            Self::Class(c) => format!("class {}", roman(c)),
            Self::AboveClass(c) => format!("between class {} and {}", roman(c), roman(c + 1)),
        }
    }
}

impl Serialize for Verdict {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.words().to_lowercase().replace(' ', "-"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn daily_wear_falls_in_the_bands() {
        assert_eq!(Verdict::daily(0.0, false), Verdict::NoContact);
        assert_eq!(Verdict::daily(0.2, true), Verdict::Loose);
        assert_eq!(Verdict::daily(1.3, true), Verdict::Comfortable);
        assert_eq!(Verdict::daily(1.5, true), Verdict::Critical);
        assert_eq!(Verdict::daily(2.1, true), Verdict::TooTight);
        assert!(Verdict::TooTight.flagged() && !Verdict::Comfortable.flagged());
    }

    #[test]
    fn compression_falls_in_ral_classes() {
        let at = |mmhg: f64| Verdict::compression(mmhg * KPA_PER_MMHG, true);
        assert_eq!(at(10.0), Verdict::BelowClassI);
        assert_eq!(at(17.0), Verdict::BelowClassI);
        assert_eq!(at(18.0), Verdict::Class(1));
        assert_eq!(at(22.0), Verdict::AboveClass(1));
        assert_eq!(at(30.0), Verdict::Class(2));
        assert_eq!(at(60.0), Verdict::Class(4));
        assert_eq!(Verdict::AboveClass(1).words(), "between class I and II");
        let json = |v: Verdict| serde_json::to_value(v).unwrap();
        assert_eq!(json(Verdict::AboveClass(1)), "between-class-i-and-ii");
        assert_eq!(json(Verdict::TooTight), "too-tight");
        assert_eq!(json(Verdict::Class(2)), "class-ii");
    }
}
