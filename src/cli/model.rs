//! `dressform model build|info|sample`: the statistical body model (paper 3.1.1).

use super::{Failure, progress_bar, within};
use dressform::atomic_output::write_atomically;
use dressform::body::scan::{self, format::Format};
use dressform::pose::body_model::{self, BodyModel, BuildOptions, MAX_BETA, file};
use dressform::pose::makehuman::MakeHuman;
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    #[command(subcommand)]
    command: ModelCommand,
}

#[derive(Debug, clap::Subcommand)]
enum ModelCommand {
    /// Build a model: from MakeHuman (sampled bodies) or from registered meshes in a template's topology.
    Build(BuildArgs),
    /// Describe a model file (the built-in one without a file): bones, k, explained variance, size.
    Info(InfoArgs),
    /// Write the body of given shape coefficients (in standard deviations) as a mesh.
    Sample(SampleArgs),
}

#[derive(Debug, clap::Args)]
struct BuildArgs {
    /// The MakeHuman assets (base.obj, rigs/, targets/).
    #[arg(long, conflicts_with_all = ["meshes", "template"], required_unless_present = "meshes")]
    makehuman: Option<PathBuf>,
    /// A folder of registered meshes (.obj, .ply, .stl) in the template's topology (canonical frame, mm).
    #[arg(long, requires = "template")]
    meshes: Option<PathBuf>,
    /// The rigged template (a model .glb) whose topology, skeleton, weights and joint regressor the meshes share.
    #[arg(long)]
    template: Option<PathBuf>,
    /// The model file to write (.glb).
    #[arg(short, long)]
    output: PathBuf,
    /// MakeHuman bodies to sample.
    #[arg(long, default_value_t = BuildOptions::default().bodies)]
    bodies: usize,
    /// Shape components to keep (k).
    #[arg(long, default_value_t = BuildOptions::default().components)]
    components: usize,
    /// The sampling seed.
    #[arg(long, default_value_t = BuildOptions::default().seed)]
    seed: u64,
}

#[derive(Debug, clap::Args)]
struct InfoArgs {
    /// A model file [default: the built-in model].
    model: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct SampleArgs {
    /// A model file [default: the built-in model].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Shape coefficients in standard deviations, comma-separated (missing ones are 0), each
    /// within ±5 (`body_model::MAX_BETA`).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    beta: Vec<f64>,
    /// The mesh to write (.obj, .ply or .stl; canonical frame, mm).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: &ModelArgs) -> Result<(), Failure> {
    match &args.command {
        ModelCommand::Build(a) => build(a),
        ModelCommand::Info(a) => info(a),
        ModelCommand::Sample(a) => sample(a),
    }
}

/// The model in `path`, or the built-in one.
pub(super) fn load(path: Option<&Path>) -> Result<BodyModel, Failure> {
    match path {
        Some(p) => file::read(p).map_err(Failure::bad_input),
        None => Ok(BodyModel::builtin()),
    }
}

fn build(args: &BuildArgs) -> Result<(), Failure> {
    let bar = progress_bar(false, 1);
    let progress = |stage: &str, done: usize, total: usize| {
        bar.set_length(total.max(1) as u64);
        bar.set_position(done as u64);
        bar.set_message(stage.to_string());
    };
    let model = match (&args.makehuman, &args.meshes, &args.template) {
        (Some(dir), _, _) => {
            bar.set_message("reading the MakeHuman assets");
            let mh = MakeHuman::load(dir).map_err(Failure::bad_input)?;
            let options =
                BuildOptions { bodies: args.bodies, components: args.components, seed: args.seed };
            body_model::from_makehuman(&mh, &options, &progress).map_err(Failure::bad_input)?
        }
        (None, Some(dir), Some(template)) => {
            let template = file::read(template).map_err(Failure::bad_input)?;
            let meshes = read_meshes(dir, &template, &progress)?;
            body_model::from_meshes(&template, &meshes, args.components, &progress)
                .map_err(Failure::bad_input)?
        }
        _ => {
            return Err(Failure::bad_input(
                "model build needs --makehuman DIR, or --meshes DIR with --template FILE",
            ));
        }
    };
    bar.finish_and_clear();
    let stored = file::at_file_precision(model.clone());
    let worst = |a: &[glam::DVec3], b: &[glam::DVec3]| {
        a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0, f64::max)
    };
    let mean_error = worst(&model.mean, &stored.mean);
    let component_error = model
        .components
        .iter()
        .zip(&stored.components)
        .map(|(a, b)| worst(a, b))
        .fold(0.0, f64::max);
    file::write(&model, &args.output).map_err(Failure::other)?;
    outln!(
        "wrote {} ({} bytes)",
        args.output.display(),
        std::fs::metadata(&args.output).map_or(0, |m| m.len())
    );
    print_summary(&stored);
    outln!(
        "stored precision: mean within {mean_error:.5} mm (f32), components within {component_error:.5} mm per sigma (i16)"
    );
    Ok(())
}

/// The meshes in `dir` (sorted by name), each with the template's vertex count.
fn read_meshes(
    dir: &Path,
    template: &BodyModel,
    progress: body_model::BuildProgress,
) -> Result<Vec<Vec<glam::DVec3>>, Failure> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Failure::bad_input(format!("{}: cannot read: {e}", dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| Format::from_path(p).is_some())
        .collect();
    paths.sort();
    paths
        .iter()
        .enumerate()
        .map(|(i, p)| {
            progress("reading meshes", i, paths.len());
            let (mesh, _) = scan::read_mesh(p).map_err(Failure::bad_input)?;
            if mesh.positions.len() != template.mean.len() {
                return Err(Failure::bad_input(format!(
                    "{}: {} vertices, the template has {}: meshes must be registered to its topology",
                    p.display(),
                    mesh.positions.len(),
                    template.mean.len()
                )));
            }
            Ok(mesh.positions)
        })
        .collect()
}

/// What `model info` says of a model (and, without its file, `model build`).
#[derive(serde::Serialize)]
struct Summary {
    /// The file, or "built-in".
    file: String,
    /// Its size, bytes.
    bytes: u64,
    /// What it was built from, how many bodies, and the sampling seed if any.
    source: String,
    bodies: usize,
    seed: Option<u64>,
    vertices: usize,
    triangles: usize,
    /// The skeleton's bones, by name.
    bones: Vec<String>,
    /// Per principal component: its standard deviation (mm), the share of the variance it
    /// explains and the cumulative share.
    components: Vec<Component>,
}

#[derive(serde::Serialize)]
struct Component {
    sigma_mm: f64,
    explained: f64,
    cumulative: f64,
}

impl Summary {
    fn of(model: &BodyModel, file: String, bytes: u64) -> Summary {
        let p = &model.provenance;
        let mut cumulative = 0.0;
        let components = (model.sigmas.iter().zip(&model.explained))
            .map(|(&sigma_mm, &explained)| {
                cumulative += explained;
                Component { sigma_mm, explained, cumulative }
            })
            .collect();
        Summary {
            file,
            bytes,
            source: p.source.clone(),
            bodies: p.bodies,
            seed: p.seed,
            vertices: model.mean.len(),
            triangles: model.triangles.len(),
            bones: model.skeleton.names.clone(),
            components,
        }
    }
}

fn print_summary(model: &BodyModel) {
    let s = Summary::of(model, String::new(), 0);
    outln!(
        "built from: {} ({} bodies{})",
        s.source,
        s.bodies,
        s.seed.map_or(String::new(), |s| format!(", seed {s}"))
    );
    outln!("vertices: {}, triangles: {}", s.vertices, s.triangles);
    outln!("bones ({}): {}", s.bones.len(), s.bones.join(" "));
    outln!("components: k = {}", s.components.len());
    outln!("  k  sigma (mm)  explained  cumulative");
    for (k, c) in s.components.iter().enumerate() {
        outln!(
            "{:>3}  {:>10.2}  {:>8.2}%  {:>9.2}%",
            k,
            c.sigma_mm,
            100.0 * c.explained,
            100.0 * c.cumulative
        );
    }
}

fn info(args: &InfoArgs) -> Result<(), Failure> {
    let model = load(args.model.as_deref())?;
    let size = match &args.model {
        Some(p) => std::fs::metadata(p).map_or(0, |m| m.len()),
        None => BodyModel::BUILTIN_GLB.len() as u64,
    };
    let file = args.model.as_ref().map_or("built-in".into(), |p| p.display().to_string());
    if args.json {
        let summary = Summary::of(&model, file, size);
        outln!("{}", serde_json::to_string_pretty(&summary).map_err(Failure::other)?);
    } else {
        outln!("file: {file} ({size} bytes)");
        print_summary(&model);
    }
    Ok(())
}

fn sample(args: &SampleArgs) -> Result<(), Failure> {
    let model = load(args.model.as_deref())?;
    for &beta in &args.beta {
        within("--beta", beta, -MAX_BETA..=MAX_BETA, " standard deviations")?;
    }
    if args.beta.len() > model.k() {
        return Err(Failure::bad_input(format!(
            "--beta: {} coefficients, the model has {}",
            args.beta.len(),
            model.k()
        )));
    }
    let format = Format::from_path(&args.output).ok_or_else(|| {
        Failure::bad_input(format!("{}: write .obj, .ply or .stl", args.output.display()))
    })?;
    let mesh = model.mesh(model.shape(&args.beta));
    write_atomically(&args.output, &format.encode(&mesh)).map_err(Failure::other)?;
    outln!("wrote {} ({} vertices)", args.output.display(), mesh.positions.len());
    Ok(())
}
