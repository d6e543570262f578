//! `dressform drive <setpoints.json> [--form <form.toml>] (--sim | --serial <path> |
//! --slcan <path> | --can <iface>) [--log <file>] [--faults <spec>] [--clamp]
//! [--tolerance <mm>] [--girth-tolerance <mm>] [--reset-faults] [--slower <factor>]
//! [--duration <s>] [--json]`.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use dressform::form::controller::motion::MAX_SLOWER;
use dressform::form::controller::simulated::SimConfig;
use dressform::form::controller::{
    DEFAULT_TOLERANCE_MM, DriveAfterError, DriveError, DriveOptions, DriveReport, LinkSpec,
    MoveError, Progress, SessionError, drive_after, plan,
};
use dressform::form::form_fit::{
    DEFAULT_GIRTH_TOLERANCE_MM, DEFAULT_HEIGHT_TOLERANCE_MM, ShapeOutcome, Targets, Tolerance,
    compare,
};
use dressform::form::setpoints::SetPoints;
use dressform::messages;
use firmware_protocol::Position;
use firmware_protocol::message::Sync;
use form_description::FormDescription;
use form_description::garment::GarmentSpec;
use std::ops::Bound;

use super::link::{self, FormArg, LinkArgs, runtime};
use super::{Failure, within};

/// The simulated form's options (with `--sim`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SimArgs {
    /// With --sim: write a candump log of the simulated bus.
    #[arg(long, value_name = "FILE")]
    log: Option<PathBuf>,
    /// With --sim: faults to inject (as `dressform sim --faults`).
    #[arg(long, value_name = "SPEC")]
    faults: Option<String>,
}

/// How the form's shape is judged after a move.
#[derive(Debug, Clone, clap::Args)]
pub struct ShapeArgs {
    /// A ring whose reached girth is off the mannequin's by more than this is "not reached"
    /// and the command exits 3, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_GIRTH_TOLERANCE_MM)]
    girth_tolerance: f64,
    /// A ring whose lifts left it off its body level by more than this is off its level and
    /// the command exits 3, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_HEIGHT_TOLERANCE_MM)]
    height_tolerance: f64,
    /// Clear latched hardware faults (a jam, an overcurrent, a broken encoder...) before
    /// moving; without it only an e-stop and a host timeout are cleared.
    #[arg(long)]
    reset_faults: bool,
}

impl ShapeArgs {
    /// The tolerances, checked.
    pub fn tolerance(&self) -> Result<Tolerance, Failure> {
        Ok(Tolerance {
            girth_mm: within("--girth-tolerance", self.girth_tolerance, 0.0.., " mm")?,
            height_mm: within("--height-tolerance", self.height_tolerance, 0.0.., " mm")?,
        })
    }

    /// Drive options with `--reset-faults`.
    pub fn options(&self) -> DriveOptions {
        DriveOptions { reset_faults: self.reset_faults, ..DriveOptions::default() }
    }
}

#[derive(Debug, clap::Args)]
pub struct DriveArgs {
    /// The set-point file (JSON, format dressform-setpoints/1).
    setpoints: PathBuf,
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    link: LinkArgs,
    #[command(flatten)]
    sim: SimArgs,
    #[command(flatten)]
    shape: ShapeArgs,
    /// Clamp positions outside an actuator's stroke into it (reported) instead of refusing
    /// the file.
    #[arg(long)]
    clamp: bool,
    /// An actuator within this of its target has arrived, mm (above 0, at most the longest
    /// stroke the wire carries: 655.34).
    #[arg(long, default_value_t = DEFAULT_TOLERANCE_MM)]
    tolerance: f64,
    /// Move this many times slower than the shortest feasible move: 1 to 65535 (a SYNC lasts
    /// at most 65535 ms, a move at least 1 ms), and no more than fits this move's SYNC.
    #[arg(long, default_value_t = 1.0)]
    slower: f64,
    /// Make the move last at least this many seconds: 0 to 65.535 (the longest SYNC).
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &DriveArgs) -> Result<(), Failure> {
    // The options first: nothing is read or sent with one out of range.
    let tolerance_mm = within(
        "--tolerance",
        args.tolerance,
        (Bound::Excluded(0.0), Bound::Included(Position::MAX.mm())),
        " mm",
    )?;
    let slower = within("--slower", args.slower, 1.0..=MAX_SLOWER, "")?;
    let longest_s = f64::from(Sync::MAX_DURATION_MS) / 1000.0;
    let min_duration = match args.duration {
        Some(s) => Duration::from_secs_f64(within("--duration", s, 0.0..=longest_s, " s")?),
        None => Duration::ZERO,
    };
    let tolerance = args.shape.tolerance()?;
    let form = args.form.load()?;
    let setpoints = SetPoints::load(&args.setpoints, &form).map_err(Failure::bad_input)?;
    let file = args.setpoints.display().to_string();
    // Refuse out-of-stroke files before touching the form.
    plan(&form, &setpoints, args.clamp).map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    let options = DriveOptions {
        clamp: args.clamp,
        tolerance_mm,
        slower,
        min_duration,
        ..args.shape.options()
    };
    let link = Link { spec: args.link.spec(), sim: args.sim.clone(), options, tolerance };
    drive_to(&form, &link, setpoints, args.json)
}

/// Where and how [`drive_to`] drives the form.
pub struct Link {
    /// Where the form is.
    pub spec: LinkSpec,
    /// The simulated form's log and faults.
    pub sim: SimArgs,
    /// The drive's options.
    pub options: DriveOptions,
    /// How far a ring may be off its girth and level.
    pub tolerance: Tolerance,
}

/// Drives `form` over `link` to `setpoints` (checked against its strokes), prints the
/// report (as JSON with `json`) and judges the shape (exit status 3 when a ring is off): the
/// end of `drive`, and of each customer's drive in `watch --drive`.
pub fn drive_to(
    form: &FormDescription,
    link: &Link,
    setpoints: SetPoints,
    json: bool,
) -> Result<(), Failure> {
    let (girths_mm, heights_mm) =
        (setpoints.target_girths_mm.clone(), setpoints.target_heights_mm.clone());
    let compute = move || Ok(((), setpoints));
    let ((), report) = execute(form, &link.spec, &link.options, &link.sim, json, compute)?;
    let targets = Targets { girths_mm: &girths_mm, heights_mm: &heights_mm };
    let shape = compare(form, &report.positions_mm, targets, link.tolerance);
    print_report(&report, &shape, json)?;
    shape_verdict(&shape)
}

/// Exit status 3 with a one-line summary when a ring is off its girth or its level by more
/// than the tolerance: the form could not take the shape.
pub fn shape_verdict(shape: &ShapeOutcome) -> Result<(), Failure> {
    match shape.summary() {
        Some(summary) => Err(Failure { message: summary, exit_code: 3 }),
        None => Ok(()),
    }
}

/// Drives `form` over `link` (the in-process simulated form for [`LinkSpec::Sim`], with
/// `sim`'s log and faults) to the set-points `compute` returns, with one progress bar per
/// node (none with `json`): [`drive_after`] on the link this process owns (its control
/// endpoint answering and the signals armed before the form is claimed). An e-stop while
/// `compute` runs ends the command at once (exit 1; its outputs are all or nothing). A failing
/// log is reported when it fails, and fails the command once the move is over.
pub fn execute<R: Send + 'static>(
    form: &FormDescription,
    link: &LinkSpec,
    options: &DriveOptions,
    sim: &SimArgs,
    json: bool,
    compute: impl FnOnce() -> Result<(R, SetPoints), Failure> + Send + 'static,
) -> Result<(R, DriveReport), Failure> {
    let steps = move || compute().map(|(value, setpoints)| (value, vec![setpoints]));
    let (value, mut reports) = execute_through(form, link, options, sim, None, json, steps)?;
    Ok((value, reports.remove(0)))
}

/// [`execute`] through several set-points in turn (one move each, one report each), the
/// simulated form wearing `garment` (with `--sim`).
pub fn execute_through<R: Send + 'static>(
    form: &FormDescription,
    link: &LinkSpec,
    options: &DriveOptions,
    sim: &SimArgs,
    garment: Option<GarmentSpec>,
    json: bool,
    compute: impl FnOnce() -> Result<(R, Vec<SetPoints>), Failure> + Send + 'static,
) -> Result<(R, Vec<DriveReport>), Failure> {
    if *link != LinkSpec::Sim && (sim.log.is_some() || sim.faults.is_some()) {
        return Err(Failure::bad_input("--log and --faults go with --sim"));
    }
    let faults = match &sim.faults {
        Some(text) => text.parse().map_err(|e| Failure::bad_input(format!("--faults: {e}")))?,
        None => Default::default(),
    };
    let display = ProgressDisplay::new(json);
    let progress = |p: &Progress| display.update(p);
    let runtime = runtime()?;
    let result = runtime.block_on(async {
        let config =
            SimConfig { faults, log: sim.log.clone(), ..SimConfig::default() }.wearing(garment);
        let owned = link::own(link, form, &config)?;
        let rig = owned.rig;
        // The simulated bus's log, watched while the form moves.
        let log_watch = async {
            let Some(rig) = &rig else { return };
            loop {
                tokio::time::sleep(LOG_CHECK).await;
                if let Some(e) = rig.log_failure() {
                    errln!("error: {e} (the move goes on)");
                    return;
                }
            }
        };
        let outcome =
            drive_after(owned.connection, form, options, compute, progress, log_watch).await;
        // The log is judged once the form moved (or failed moving).
        let moved = matches!(outcome, Ok(_) | Err(DriveAfterError::Drive(_)));
        if moved && let Some(rig) = rig {
            rig.finish().map_err(link::sim_failure)?;
        }
        outcome.map_err(Failure::from)
    });
    display.finish();
    result
}

/// How often a simulated bus's log is checked for write errors.
const LOG_CHECK: Duration = Duration::from_millis(100);

impl From<DriveAfterError<Failure>> for Failure {
    fn from(e: DriveAfterError<Failure>) -> Self {
        match e {
            DriveAfterError::Claim(e) => DriveError::from(e).into(),
            DriveAfterError::Thread(e) => Failure::other(e),
            DriveAfterError::Computation(failure) => failure,
            DriveAfterError::Drive(e) => e.into(),
        }
    }
}

impl From<DriveError> for Failure {
    fn from(e: DriveError) -> Self {
        match e {
            // Out of stroke, or a move longer than a SYNC carries: what was asked.
            DriveError::OutOfStroke(_) | DriveError::Move(MoveError::TooLong { .. }) => {
                Failure::bad_input(e)
            }
            DriveError::NotReached(report) => {
                print_table(&report);
                Failure::other(DriveError::NotReached(report))
            }
            DriveError::Session(SessionError::Latched(_)) => Failure::other(format!(
                "{e}\ncheck the form, then clear them with `dressform reset` (or drive with --reset-faults)"
            )),
            e => Failure::other(e),
        }
    }
}

fn print_report(report: &DriveReport, shape: &ShapeOutcome, json: bool) -> Result<(), Failure> {
    for (id, asked, used) in &report.clamped {
        let (asked, used) = (messages::number(*asked), messages::number(*used));
        errln!("warning: {id}: {asked} mm is outside the stroke, clamped to {used} mm");
    }
    for warning in &report.warnings {
        errln!("warning: {warning}");
    }
    if json {
        // The report, with the shape beside its fields.
        let mut value = serde_json::to_value(report).map_err(Failure::other)?;
        value["shape"] = serde_json::to_value(shape).map_err(Failure::other)?;
        let text = serde_json::to_string_pretty(&value).map_err(Failure::other)?;
        outln!("{text}");
    } else {
        print_table(report);
        if !shape.rings.is_empty() {
            outln!(
                "{:<12} {:>10} {:>10} {:>8} {:>8} {:>8} {:>8}  status",
                "ring",
                "mannequin",
                "form",
                "error",
                "level",
                "height",
                "error"
            );
            let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.1}"));
            for r in &shape.rings {
                outln!(
                    "{:<12} {:>10} {:>10.1} {:>8.1} {:>8} {:>8.1} {:>8.1}  {}",
                    r.ring,
                    mm(r.target_mm),
                    r.reached_mm,
                    r.error_mm(),
                    mm(r.target_height_mm),
                    r.reached_height_mm,
                    r.height_error_mm(),
                    shape.status(r)
                );
            }
        }
    }
    Ok(())
}

fn print_table(report: &DriveReport) {
    outln!(
        "{} on {}: {} actuators, SYNC {} ms, done after {} ms",
        report.form,
        report.device,
        report.actuators.len(),
        report.duration_ms,
        report.elapsed_ms
    );
    outln!(
        "{:<18} {:>4} {:>9} {:>9} {:>8}  status",
        "actuator",
        "node",
        "target",
        "reached",
        "error"
    );
    let mm = |v: Option<f64>| v.map_or_else(|| "-".to_string(), |v| format!("{v:.2}"));
    for a in &report.actuators {
        outln!(
            "{:<18} {:>4} {:>9.2} {:>9} {:>8}  {}",
            a.id,
            a.node,
            a.target_mm,
            mm(a.reached_mm),
            mm(a.error_mm),
            if a.within_tolerance { "ok" } else { "NOT REACHED" }
        );
    }
}

/// One progress bar per node, on standard error (hidden off-terminal and with `--json`).
struct ProgressDisplay {
    multi: Option<indicatif::MultiProgress>,
    bars: std::cell::RefCell<BTreeMap<u8, indicatif::ProgressBar>>,
}

impl ProgressDisplay {
    fn new(json: bool) -> Self {
        let multi = (!json).then(indicatif::MultiProgress::new);
        Self { multi, bars: Default::default() }
    }

    fn update(&self, progress: &Progress) {
        let Some(multi) = &self.multi else { return };
        let mut bars = self.bars.borrow_mut();
        for node in &progress.nodes {
            let bar = bars.entry(node.node).or_insert_with(|| {
                let bar = multi.add(indicatif::ProgressBar::new(node.total as u64));
                if let Ok(style) = indicatif::ProgressStyle::with_template(
                    "{prefix:>14} [{bar:16}] {pos}/{len} {msg}",
                ) {
                    bar.set_style(style.progress_chars("=> "));
                }
                bar.set_prefix(node.label.clone());
                bar
            });
            bar.set_position(node.within as u64);
            let worst = node
                .worst_mm
                .map_or_else(|| "position unknown".into(), |w| format!("{w:.2} mm to go"));
            bar.set_message(worst);
        }
    }

    fn finish(&self) {
        for bar in self.bars.borrow().values() {
            bar.finish_and_clear();
        }
    }
}
