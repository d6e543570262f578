//! `dressform watch <IN> -o <OUT> [--settle S] [--poll S] [--drive LINK]`: each scan that
//! lands in IN processed into `OUT/<its stem>/` (see [`dressform::intake::watch`]), one
//! progress line each; with `--drive`, the form shaped for each new customer after a y/N on
//! the terminal. SIGINT or SIGTERM finishes the scan in hand, then stops.

use super::batch::{IntakeArgs, progress_line};
use super::drive::{Link, ShapeArgs, SimArgs, drive_to};
use super::link::LinkArgs;
use super::{Failure, warn, within};
use dressform::form::setpoints::SetPoints;
use dressform::intake::process::{Outcome, Processor};
use dressform::intake::summary::Row;
use dressform::intake::watch::{Handled, WatchOptions, watch};
use dressform::run::outputs::SETPOINTS;
use std::io::BufRead;
use std::path::PathBuf;
use std::time::Duration;

/// The default settle time (s): a copier that pauses longer between writes than this is
/// taken as done, so it is well above a network copy's pauses, and short enough that a
/// customer waits a moment only.
const DEFAULT_SETTLE_S: f64 = 5.0;
/// The longest settle time or poll interval (s): an hour.
const LONGEST_S: f64 = 3600.0;

#[derive(Debug, clap::Args)]
// The link is needed with --drive only.
#[command(mut_group("LinkArgs", |g| g.required(false)))]
pub struct WatchArgs {
    /// The folder the scanner writes into.
    input: PathBuf,
    /// The output folder: OUT/<scan's stem>/ per scan, and journal.jsonl.
    #[arg(short, long)]
    out: PathBuf,
    /// A scan counts once its size has not changed for this long (s), or when renamed in.
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_SETTLE_S)]
    settle: f64,
    /// List the folder every SECONDS instead of waiting for its events (network shares,
    /// where none are delivered).
    #[arg(long, value_name = "SECONDS")]
    poll: Option<f64>,
    /// Shape the form for each new customer, after a y/N confirmation on the terminal; the
    /// link is one of --sim, --serial, --slcan, --can.
    #[arg(long)]
    drive: bool,
    #[command(flatten)]
    link: Option<LinkArgs>,
    #[command(flatten)]
    sim: SimArgs,
    #[command(flatten)]
    shape: ShapeArgs,
    #[command(flatten)]
    intake: IntakeArgs,
}

pub fn run(args: &WatchArgs) -> Result<(), Failure> {
    let settle = within("--settle", args.settle, 0.0..=LONGEST_S, " s")?;
    let poll = match args.poll {
        Some(s) => Some(Duration::from_secs_f64(within("--poll", s, 0.01..=LONGEST_S, " s")?)),
        None => None,
    };
    let link = match (args.drive, &args.link) {
        (true, Some(link)) => Some(Link {
            spec: link.spec(),
            sim: args.sim.clone(),
            options: args.shape.options(),
            tolerance: args.shape.tolerance()?,
        }),
        (true, None) => {
            return Err(Failure::bad_input(
                "--drive needs the form's link: --sim, --serial PATH, --slcan PATH or --can IFACE",
            ));
        }
        (false, Some(_)) => {
            return Err(Failure::bad_input("a link (--sim, --serial...) goes with --drive"));
        }
        (false, None) => None,
    };
    if !args.input.is_dir() {
        return Err(Failure::bad_input(format!("{}: not a folder", args.input.display())));
    }
    let processor = args.intake.processor()?;
    let options =
        WatchOptions { settle: Duration::from_secs_f64(settle), poll, frame: args.intake.frame() };
    let stop = super::signals::finish_on_signal();
    errln!(
        "watching {} (scans count after {settle} s unchanged, or when renamed in); outputs in {}; Ctrl-C to stop",
        args.input.display(),
        args.out.display()
    );
    let handled = |h: Handled| {
        let outcome = h.result.cloned().map_err(|(e, _)| e.to_string());
        let row = Row::new(&h.job.customer, &outcome, h.seconds);
        outln!("{}", progress_line(&row));
        match (&h.result, &link) {
            (Ok(Outcome::Done(_, warnings)), link) => {
                for w in warnings {
                    warn(&h.job.path.display().to_string(), w);
                }
                if let Some(link) = link {
                    offer_drive(&processor, link, &args.out.join(&h.job.customer), &h.job.customer);
                }
            }
            (Err((_, to)), _) => outln!("  moved to {}", to.display()),
            _ => {}
        }
    };
    watch(&processor, &args.input, &args.out, &options, stop, handled).map_err(Failure::other)?;
    errln!("stopped");
    Ok(())
}

/// Asks on the terminal whether to shape the form for `customer` (whose outputs are in
/// `dir`), and drives it on yes; a failed drive is reported, and watching goes on.
fn offer_drive(processor: &Processor, link: &Link, dir: &std::path::Path, customer: &str) {
    out!("Shape the form for {customer}? [y/N] ");
    let mut answer = String::new();
    if std::io::stdin().lock().read_line(&mut answer).is_err()
        || !answer.trim().eq_ignore_ascii_case("y")
    {
        outln!("  not driven");
        return;
    }
    let form = &processor.form;
    let driven = SetPoints::load(&dir.join(SETPOINTS), form)
        .map_err(Failure::bad_input)
        .and_then(|setpoints| drive_to(form, link, setpoints, false));
    if let Err(e) = driven {
        errln!("error: {customer}: {}", e.message);
    }
}
