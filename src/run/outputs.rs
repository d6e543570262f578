//! What the commands write: a pipeline result as its set of files, by name and content.
//! [`crate::atomic_output`] commits such a set into a directory, all or nothing.
//!
//! | file | what |
//! |---|---|
//! | `mannequin.<ext>` | the mannequin, as the [`Export`] says (format, units, axes, frame) |
//! | [`PROFILES`] | its sections ([`crate::shape::profiles`]), what a form is fitted to |
//! | [`MEASUREMENTS`] | Table 1 and Fig. 11 ([`crate::shape::measure::Comparison`]); after pose symmetry, with the scan's column ([`crate::run::reconstruct::MeasurementsReport`]) |
//! | [`SETPOINTS`] | with a form: the set-points ([`crate::form::setpoints`]) |
//! | [`FORM_FIT`] | with a form: its rings over the mannequin and each ring from above |
//! | [`PREVIEW`] | the scan (and the pose-symmetric scan) and the mannequin in three views |
//! | [`SECTIONS`] | the chest, waist and hip sections of both (paper Fig. 9 and 11) |
//! | [`REPORT`] | the customer report: the pictures, the measurements, the form's fit ([`crate::run::report`]) |
//! | `posed.<ext>` | after pose symmetry: the pose-symmetric scan, as the [`Export`] says |
//! | [`RIGGED`] | after pose symmetry: the scan with the fitted skeleton and its skin weights |
//! | [`FIT`] | after pose symmetry: the fit ([`crate::run::reconstruct::FitReport`]) |
//!
//! `fit-test` writes a set of its own: `fit-test.json`, [`GARMENT_FIT`], [`SWEEP`] with a size
//! sweep, and its [`REPORT`] ([`fit_test_report`]).

use crate::atomic_output::OutputSet;
use crate::body::scan::Scan;
use crate::body::scan::format::Export;
use crate::form::fit_test::FitTest;
use crate::form::fit_test::sweep::Sweep;
use crate::form::form_fit::FormFit;
use crate::form::setpoints::SetPoints;
use crate::run::pipeline::Symmetrized;
use crate::run::preview::{form_fit_png, preview_png, sections_svg};
use crate::run::reconstruct::{AsScanned, MeasurementsReport, Reposed};
use crate::run::report::{self, Figure, FitTestPart, FormPart, Measured, Report, SweepPart};
use form_description::FormDescription;
use rayon::prelude::*;

/// Makes one file's bytes.
type Job<'a> = Box<dyn FnOnce() -> Result<Vec<u8>, serde_json::Error> + Send + 'a>;

/// The mannequin's file name without its extension (the export adds it).
pub const MANNEQUIN: &str = "mannequin";
/// The mannequin's profiles.
pub const PROFILES: &str = "profiles.json";
/// The measurements of the scan and the mannequin.
pub const MEASUREMENTS: &str = "measurements.json";
/// The form's set-points.
pub const SETPOINTS: &str = "setpoints.json";
/// The picture of the form's fit.
pub const FORM_FIT: &str = "form-fit.png";
/// The picture of the scan and the mannequin.
pub const PREVIEW: &str = "preview.png";
/// The picture of the sections.
pub const SECTIONS: &str = "sections.svg";
/// The pose-symmetric scan's file name without its extension (the export adds it).
pub const POSED: &str = "posed";
/// The scan with the fitted model's skeleton and skin weights (glTF, whatever the export).
pub const RIGGED: &str = "rigged.glb";
/// What the fit found and the symmetric pose.
pub const FIT: &str = "fit.json";
/// The customer report.
pub const REPORT: &str = "report.html";
/// The fit test's picture of the garment on the form (`fit-test`).
pub const GARMENT_FIT: &str = "fit.png";
/// The fit test's size sweep (`fit-test --sweep`).
pub const SWEEP: &str = "sweep.svg";

/// The files of a mannequin made from a scan (`symmetrize`), after pose symmetry
/// (`reconstruct`), with the form's set-points when a form was fitted to it (`run`, `demo`).
#[derive(Debug, Clone, Copy)]
pub struct Outputs<'a> {
    result: &'a Symmetrized,
    /// The body the mannequin was made from.
    scan: &'a Scan,
    export: &'a Export,
    /// With a form: the form, its fit and set-points.
    form: Option<(&'a FormDescription, &'a FormFit, &'a SetPoints)>,
    /// The input scan, how it was re-posed and what it measured as it stood, after pose
    /// symmetry.
    reposed: Option<(&'a Scan, &'a Reposed, &'a AsScanned)>,
    /// Who the report names (default: the scan's file stem).
    customer: Option<&'a str>,
}

impl<'a> Outputs<'a> {
    /// The files of `result`, the mannequin of `scan`, its own file written as `export` says.
    pub fn of(result: &'a Symmetrized, scan: &'a Scan, export: &'a Export) -> Self {
        Outputs { result, scan, export, form: None, reposed: None, customer: None }
    }

    /// The files of `result`, the mannequin of the pose-symmetric scan of `reposed`, made from
    /// the scan `input` (canonical frame, as fitted), which measured `as_scanned` as it stood;
    /// the mannequin and the pose-symmetric scan written as `export` says.
    pub fn reposed(
        result: &'a Symmetrized,
        reposed: &'a Reposed,
        as_scanned: &'a AsScanned,
        input: &'a Scan,
        export: &'a Export,
    ) -> Self {
        let of = Self::of(result, &reposed.posed, export);
        Outputs { reposed: Some((input, reposed, as_scanned)), ..of }
    }

    /// With a form fitted to the mannequin: its fit and set-points.
    pub fn with_form(
        self,
        form: &'a FormDescription,
        fit: &'a FormFit,
        setpoints: &'a SetPoints,
    ) -> Self {
        Outputs { form: Some((form, fit, setpoints)), ..self }
    }

    /// With the customer the report names (instead of the scan's file stem).
    pub fn with_customer(self, customer: &'a str) -> Self {
        Outputs { customer: Some(customer), ..self }
    }

    /// The set of files (see the module documentation). The files are made in parallel (and
    /// the report's measurement of the body beside them), then added in a fixed order.
    pub fn files(&self) -> Result<OutputSet, serde_json::Error> {
        let (result, scan, export) = (self.result, self.scan, self.export);
        let mut jobs: Vec<(String, Job<'a>)> = Vec::new();
        let mut add = |name: &str, job: Job<'a>| jobs.push((name.to_string(), job));
        add(
            &export.file_name(MANNEQUIN),
            Box::new(move || Ok(result.mannequin_file(export, &scan.frame))),
        );
        add(PROFILES, Box::new(move || serde_json::to_vec_pretty(&result.profiles)));
        if let Some((form, fit, setpoints)) = self.form {
            add(SETPOINTS, Box::new(move || Ok(setpoints.to_json_string().into_bytes())));
            add(FORM_FIT, Box::new(move || Ok(form_fit_png(result, fit, form))));
        }
        add(SECTIONS, Box::new(move || Ok(sections_svg(&scan.body, result).into_bytes())));
        match self.reposed {
            None => {
                add(MEASUREMENTS, Box::new(move || serde_json::to_vec_pretty(&result.comparison)));
                add(PREVIEW, Box::new(move || Ok(preview_png(&[(&scan.body, "scan")], result))));
            }
            Some((input, reposed, as_scanned)) => {
                add(
                    MEASUREMENTS,
                    Box::new(move || {
                        serde_json::to_vec_pretty(&MeasurementsReport::new(
                            as_scanned,
                            &result.comparison,
                        ))
                    }),
                );
                add(
                    PREVIEW,
                    Box::new(move || {
                        let bodies = [(&input.body, "scan"), (&scan.body, "pose-symmetric")];
                        Ok(preview_png(&bodies, result))
                    }),
                );
                add(
                    &export.file_name(POSED),
                    Box::new(move || Ok(export.encode(&export.place(&scan.body, &scan.frame).0))),
                );
                add(RIGGED, Box::new(move || Ok(reposed.rigged_glb(input))));
                add(FIT, Box::new(move || serde_json::to_vec_pretty(&reposed.fit_report())));
            }
        }
        let body = match self.reposed {
            None => "the scan",
            Some(_) => "the pose-symmetric scan",
        };
        let (files, measured) = rayon::join(
            || {
                let made = jobs.into_par_iter().map(|(name, job)| job().map(|bytes| (name, bytes)));
                made.collect::<Vec<_>>()
            },
            || Measured::of(scan, &result.regions, body),
        );
        let mut set = OutputSet::new();
        for file in files {
            let (name, bytes) = file?;
            set.add(name, bytes);
        }
        let html = report::render(&self.report(&set, measured));
        set.add(REPORT, html);
        Ok(set)
    }

    /// The customer report of these outputs, its pictures those of `set` (their files).
    fn report<'s>(&self, set: &'s OutputSet, measured: Result<Measured, String>) -> Report<'s>
    where
        'a: 's,
    {
        let figure = |file, caption| Figure::of(set, file, caption);
        let preview = match self.reposed {
            None => "The scan and the mannequin, front, side and back",
            Some(_) => {
                "The scan as it stood, the pose-symmetric scan and the mannequin, front, side \
                 and back"
            }
        };
        let sections = "The chest, waist and hip seen from above, front at the bottom: the \
                        scan, its halves mirrored and the symmetric mannequin";
        let form_fit = "The form's rings over the mannequin, and each ring from above, each \
                        panel coloured by its gap";
        let form =
            self.form.map(|(_, fit, _)| FormPart { fit, figure: figure(FORM_FIT, form_fit) });
        let source = &self.scan.source;
        let stem = source.file_stem().unwrap_or(source.as_os_str()).to_string_lossy();
        Report {
            customer: self.customer.map_or_else(|| stem.into_owned(), str::to_string),
            date: report::today_utc(),
            body: [figure(PREVIEW, preview), figure(SECTIONS, sections)]
                .into_iter()
                .flatten()
                .collect(),
            measurements: Some(measured),
            form,
            fit_test: None,
        }
    }
}

/// The customer report of a garment's fit test on `customer`: at the customer's girths (`fit`)
/// and through the size `sweep`, when one was run; its pictures the files of `set`
/// ([`GARMENT_FIT`], [`SWEEP`]).
pub fn fit_test_report<'s>(
    customer: String,
    fit: &'s FitTest,
    sweep: Option<&'s Sweep>,
    set: &'s OutputSet,
) -> Report<'s> {
    let garment = "Each ring the garment covers seen from above, its panels coloured by their \
                   pressure";
    let swept = "Each ring's mean pressure through the size sweep";
    let fit_test = FitTestPart {
        fit,
        figure: Figure::of(set, GARMENT_FIT, garment),
        sweep: sweep.map(|sweep| SweepPart { sweep, figure: Figure::of(set, SWEEP, swept) }),
    };
    Report {
        customer,
        date: report::today_utc(),
        body: Vec::new(),
        measurements: None,
        form: None,
        fit_test: Some(fit_test),
    }
}
