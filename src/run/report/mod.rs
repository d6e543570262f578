//! `report.html`, the customer report (issue 33): what a tailor or a fit technician reads,
//! on screen or printed on A4. One file that stands alone: its pictures inside it (PNG as
//! `data:` URIs, SVG inline), no script, nothing fetched, so it opens from a file share or an
//! e-mail. A [`Report`] is made from what a command's outputs already hold
//! ([`crate::run::outputs::Outputs`], the fit test's files) and [`render`]ed by one template.
//!
//! What it shows, each part when the command made it: a header (the customer, the date, the
//! tool's version); the body (`preview.png`: the scan, the pose-symmetric scan, the mannequin;
//! `sections.svg`); the measurement table ([`measured`]: the ISO 8559-1 dimensions with their
//! definitions, "not measured" and the reason where a number was held back); the form's fit
//! (per ring its height and girth against the body's, the gaps, its status; `form-fit.png`);
//! the garment's fit test (per ring ease, pressure, verdict; `fit.png`; the size sweep and
//! `sweep.svg`).

pub mod definitions;
pub mod embed;
mod html;
pub mod measured;

pub use html::render;
pub use measured::Measured;

use crate::atomic_output::OutputSet;
use crate::form::fit_test::FitTest;
use crate::form::fit_test::sweep::Sweep;
use crate::form::form_fit::FormFit;
use std::time::{SystemTime, UNIX_EPOCH};

/// A picture of the report: one of the output set's files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figure<'a> {
    /// The file's name (`preview.png`): a `.svg` goes in inline, anything else as a PNG.
    pub file: &'static str,
    /// Its bytes.
    pub bytes: &'a [u8],
    /// What it shows, in a sentence.
    pub caption: &'static str,
}

impl<'a> Figure<'a> {
    /// The file `file` of `set`, if it has one, with its caption.
    pub fn of(set: &'a OutputSet, file: &'static str, caption: &'static str) -> Option<Self> {
        set.get(file).map(|bytes| Figure { file, bytes, caption })
    }
}

/// The form fitted to the mannequin.
#[derive(Debug, Clone, Copy)]
pub struct FormPart<'a> {
    /// The fit: each ring's height and girth against the body's, its gaps and status.
    pub fit: &'a FormFit,
    /// `form-fit.png`.
    pub figure: Option<Figure<'a>>,
}

/// A garment's fit test on the form.
#[derive(Debug, Clone, Copy)]
pub struct FitTestPart<'a> {
    /// The fit at the customer's girths.
    pub fit: &'a FitTest,
    /// `fit.png`.
    pub figure: Option<Figure<'a>>,
    /// The size sweep, when one was run.
    pub sweep: Option<SweepPart<'a>>,
}

/// A fit test's size sweep.
#[derive(Debug, Clone, Copy)]
pub struct SweepPart<'a> {
    /// What the sweep found.
    pub sweep: &'a Sweep,
    /// `sweep.svg`.
    pub figure: Option<Figure<'a>>,
}

/// What `report.html` shows (see the module documentation); a part left out (`None`, empty)
/// is not shown.
#[derive(Debug, Clone)]
pub struct Report<'a> {
    /// Who it is about: the scan's file stem, or the demo's customer.
    pub customer: String,
    /// The day it was made, `YYYY-MM-DD` (UTC): [`today_utc`].
    pub date: String,
    /// The body's pictures: `preview.png`, `sections.svg`.
    pub body: Vec<Figure<'a>>,
    /// The measurements, or why the body could not be measured.
    pub measurements: Option<Result<Measured, String>>,
    /// The form's fit, when a form was fitted (`run`, `demo`).
    pub form: Option<FormPart<'a>>,
    /// The garment's fit test (`fit-test`).
    pub fit_test: Option<FitTestPart<'a>>,
}

/// Seconds in a day (UTC days have no leap seconds in Unix time).
const SECONDS_PER_DAY: u64 = 86_400;
/// Days from 0000-03-01 to 1970-01-01 in the proleptic Gregorian calendar (Hinnant's
/// `civil_from_days`: counting from March puts the leap day at the end of the year).
const DAYS_TO_UNIX_EPOCH: i64 = 719_468;
/// Days in 400 Gregorian years, after which the calendar repeats.
const DAYS_PER_ERA: i64 = 146_097;

/// Today's date in UTC, `YYYY-MM-DD`, from the system clock (1970-01-01 on a clock set before
/// it), or from `SOURCE_DATE_EPOCH` (seconds since 1970) when it is set: the reproducible-builds
/// convention, so that a report made twice is the same bytes whatever the day.
pub fn today_utc() -> String {
    let clock = || SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let seconds = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or_else(clock);
    let (year, month, day) = civil_from_days((seconds / SECONDS_PER_DAY) as i64);
    format!("{year:04}-{month:02}-{day:02}")
}

/// The Gregorian date (year, month, day) `days` after 1970-01-01: Howard Hinnant's
/// `civil_from_days` ("chrono-Compatible Low-Level Date Algorithms", 2013).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + DAYS_TO_UNIX_EPOCH;
    let era = z.div_euclid(DAYS_PER_ERA);
    let day_of_era = z.rem_euclid(DAYS_PER_ERA);
    let year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    // Months from March: 153 days in every five.
    let month_from_march = (5 * day_of_year + 2) / 153;
    let day = (day_of_year - (153 * month_from_march + 2) / 5 + 1) as u32;
    let month = if month_from_march < 10 { month_from_march + 3 } else { month_from_march - 9 };
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    (year, month as u32, day)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn days_since_1970_are_gregorian_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(19_723), (2024, 1, 1));
        assert_eq!(civil_from_days(20_513), (2026, 3, 1));
        let today = today_utc();
        assert!(today.len() == 10 && today.as_bytes()[4] == b'-', "{today}");
    }
}
