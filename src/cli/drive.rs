//! `dressform drive <setpoints.json> [--form <form.toml>] (--sim | --serial <path> |
//! --slcan <path> | --can <iface>) [--log <file>] [--faults <spec>] [--clamp]
//! [--tolerance <mm>] [--slower <factor>] [--duration <s>] [--json]`.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

use dressform::controller::simulated::{SimConfig, drive_on_sim};
use dressform::controller::{
    Connection, DEFAULT_TOLERANCE_MM, DriveError, DriveOptions, DriveReport, LinkSpec, Progress,
    drive, plan,
};
use dressform::setpoints::SetPoints;
use sim::form::FormDescription;

use super::Failure;

/// Where the form is.
#[derive(Debug, Clone, clap::Args)]
#[group(required = true, multiple = false)]
pub struct LinkArgs {
    /// The in-process simulated form (no hardware needed).
    #[arg(long)]
    sim: bool,
    /// A serial port speaking the protocol's serial mapping (1 Mbaud).
    #[arg(long, value_name = "PATH")]
    serial: Option<PathBuf>,
    /// An slcan (Lawicel) USB-CAN adapter on a serial port (classic CAN, 1 Mbit/s).
    #[arg(long, value_name = "PATH")]
    slcan: Option<PathBuf>,
    /// A SocketCAN interface (can0, vcan0...).
    #[arg(long, value_name = "IFACE")]
    can: Option<String>,
}

impl LinkArgs {
    pub fn spec(&self) -> LinkSpec {
        match (&self.serial, &self.slcan, &self.can) {
            (Some(path), _, _) => LinkSpec::Serial(path.clone()),
            (_, Some(path), _) => LinkSpec::Slcan(path.clone()),
            (_, _, Some(iface)) => LinkSpec::Can(iface.clone()),
            _ => LinkSpec::Sim,
        }
    }
}

/// Loads `--form`, or the built-in reference form.
pub fn load_form(path: Option<&PathBuf>) -> Result<FormDescription, Failure> {
    match path {
        Some(path) => FormDescription::load(path).map_err(Failure::bad_input),
        None => Ok(sim::form::reference()),
    }
}

/// A current-thread runtime for one command.
pub fn runtime() -> Result<tokio::runtime::Runtime, Failure> {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| Failure::other(format!("cannot start the runtime: {e}")))
}

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

#[derive(Debug, clap::Args)]
pub struct DriveArgs {
    /// The set-point file (JSON, format dressform-setpoints/1).
    setpoints: PathBuf,
    /// The form description (TOML) [default: the built-in reference form].
    #[arg(long)]
    form: Option<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
    #[command(flatten)]
    sim: SimArgs,
    /// Clamp positions outside an actuator's stroke into it (reported) instead of refusing
    /// the file.
    #[arg(long)]
    clamp: bool,
    /// An actuator within this of its target has arrived, mm.
    #[arg(long, default_value_t = DEFAULT_TOLERANCE_MM)]
    tolerance: f64,
    /// Move this many times slower than the shortest feasible move (≥ 1).
    #[arg(long, default_value_t = 1.0)]
    slower: f64,
    /// Make the move last at least this many seconds.
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &DriveArgs) -> Result<(), Failure> {
    let form = load_form(args.form.as_ref())?;
    let setpoints = SetPoints::load(&args.setpoints, &form).map_err(Failure::bad_input)?;
    let file = args.setpoints.display().to_string();
    // Refuse out-of-stroke files before touching the form.
    plan(&form, &setpoints, args.clamp).map_err(|e| Failure::bad_input(format!("{file}: {e}")))?;
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        return Err(Failure::bad_input("--tolerance: must be a positive number of mm"));
    }
    if !(args.slower.is_finite() && args.slower >= 1.0) {
        return Err(Failure::bad_input("--slower: must be a number ≥ 1"));
    }
    let min_duration = match args.duration {
        Some(s) if s.is_finite() && (0.0..=65.535).contains(&s) => Duration::from_secs_f64(s),
        Some(_) => return Err(Failure::bad_input("--duration: must be 0..=65.535 seconds")),
        None => Duration::ZERO,
    };
    let options = DriveOptions {
        clamp: args.clamp,
        tolerance_mm: args.tolerance,
        slower: args.slower,
        min_duration,
        ..DriveOptions::default()
    };
    let report = execute(&form, &setpoints, &args.link.spec(), &options, &args.sim, args.json)?;
    print_report(&report, args.json)
}

/// Drives `form` to `setpoints` over `link` (the in-process simulated form for
/// [`LinkSpec::Sim`], with `sim`'s log and faults), with one progress bar per node (none with
/// `json`); Ctrl-C broadcasts an emergency stop.
pub fn execute(
    form: &FormDescription,
    setpoints: &SetPoints,
    link: &LinkSpec,
    options: &DriveOptions,
    sim: &SimArgs,
    json: bool,
) -> Result<DriveReport, Failure> {
    if *link != LinkSpec::Sim && (sim.log.is_some() || sim.faults.is_some()) {
        return Err(Failure::bad_input("--log and --faults go with --sim"));
    }
    let faults = match &sim.faults {
        Some(text) => text.parse().map_err(Failure::bad_input)?,
        None => Default::default(),
    };
    let (stop_tx, stop) = tokio::sync::watch::channel(false);
    let options = DriveOptions { stop: Some(stop), ..options.clone() };
    let display = ProgressDisplay::new(json);
    let progress = |p: &Progress| display.update(p);
    let runtime = runtime()?;
    let result = runtime.block_on(async {
        tokio::spawn(async move {
            if tokio::signal::ctrl_c().await.is_ok() {
                let _ = stop_tx.send(true);
            }
        });
        match link {
            LinkSpec::Sim => {
                let config = SimConfig { faults, log: sim.log.clone(), ..SimConfig::default() };
                drive_on_sim(form, setpoints, &options, &config, progress)
                    .await
                    .map(|(report, _)| report)
                    .map_err(|e| match e {
                        dressform::controller::simulated::SimDriveError::Drive(d) => d.into(),
                        other => Failure::bad_input(other),
                    })
            }
            spec => {
                let connection = Connection::open(spec).map_err(Failure::other)?;
                drive(connection, form, setpoints, &options, progress).await.map_err(Into::into)
            }
        }
    });
    display.finish();
    result
}

impl From<DriveError> for Failure {
    fn from(e: DriveError) -> Self {
        match e {
            DriveError::OutOfStroke(_) => Failure::bad_input(e),
            DriveError::NotReached(report) => {
                print_table(&report);
                Failure::other(DriveError::NotReached(report))
            }
            e => Failure::other(e),
        }
    }
}

fn print_report(report: &DriveReport, json: bool) -> Result<(), Failure> {
    for (id, asked, used) in &report.clamped {
        errln!("warning: {id}: {asked} mm is outside the stroke, clamped to {used} mm");
    }
    for warning in &report.warnings {
        errln!("warning: {warning}");
    }
    if json {
        let text = serde_json::to_string_pretty(report).map_err(Failure::other)?;
        outln!("{text}");
    } else {
        print_table(report);
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
