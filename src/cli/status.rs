//! `dressform status [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--json]`: every node's identity, state, faults and positions, without
//! changing anything.

use std::path::PathBuf;
use std::time::Duration;

use dressform::controller::transport::sim::SimBus;
use dressform::controller::{Connection, LinkSpec, NodeReport, status};
use sim::bus::can::{CanBus, CanKind};
use sim::robot::{SimOptions, SimulatedForm};

use super::Failure;
use super::drive::{LinkArgs, load_form, runtime};

/// How long to listen for heartbeats and feedback.
const LISTEN: Duration = Duration::from_millis(300);

#[derive(Debug, clap::Args)]
pub struct StatusArgs {
    /// The form description (TOML) [default: the built-in reference form].
    #[arg(long)]
    form: Option<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &StatusArgs) -> Result<(), Failure> {
    let form = load_form(args.form.as_ref())?;
    let reports = runtime()?.block_on(async {
        match args.link.spec() {
            LinkSpec::Sim => {
                let bus = CanBus::new(CanKind::CLASSIC_1M);
                let _form =
                    SimulatedForm::on_can(&form, &bus, &Default::default(), &SimOptions::default())
                        .map_err(Failure::bad_input)?;
                status(SimBus::attach(&bus), &form, LISTEN).await.map_err(Failure::other)
            }
            spec => {
                let connection = Connection::open(&spec).map_err(Failure::other)?;
                status(connection, &form, LISTEN).await.map_err(Failure::other)
            }
        }
    })?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&reports).map_err(Failure::other)?);
    } else {
        print(&reports);
    }
    Ok(())
}

fn print(reports: &[NodeReport]) {
    for r in reports {
        let state = r.state.as_deref().unwrap_or("silent");
        let version = match (&r.protocol, &r.firmware) {
            (Some(p), Some(f)) => format!("protocol {p}, firmware {f}"),
            _ => "not identified".into(),
        };
        let faults = if r.faults.is_empty() {
            String::new()
        } else {
            format!(", faults {}", r.faults.join("|"))
        };
        outln!("node {}: {state} ({version}){faults}", r.node);
        for problem in &r.problems {
            outln!("  problem: {problem}");
        }
        for (id, mm) in &r.positions_mm {
            let p = mm.map_or_else(|| "unknown".to_string(), |v| format!("{v:.2} mm"));
            outln!("  {id:<18} {p}");
        }
    }
}
