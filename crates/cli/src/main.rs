//! The `raylab` command: a thin front end over the library crates. It parses arguments,
//! reports progress and results, and decides exit codes; it renders nothing itself.

mod commands;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "raylab", version, about = "A CPU ray tracer and a laboratory of acceleration structures", long_about = "A CPU ray tracer and a laboratory of acceleration structures.\n\nWith no command, renders the embedded default scene to raylab.png.")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (or the embedded default scene) to an image
    Render(commands::render::RenderArgs),
    /// Print what a scene contains, without rendering
    Inspect(commands::inspect::InspectArgs),
    /// Compare acceleration structures side by side on the same rays
    Bench(commands::bench::BenchArgs),
    /// Trace a ray file through a scene or mesh
    Trace(commands::trace::TraceArgs),
    /// Compare two images: MSE, RMSE, relative MSE, and a false-colour difference image
    Compare(commands::compare::CompareArgs),
    /// Measure how light-sampling strategies converge: MSE against samples and time
    Converge(commands::converge::ConvergeArgs),
    /// Write a procedural test scene of any size (Haines' Standard Procedural Databases)
    Gen(commands::gen::GenArgs),
    /// Bake a high-resolution mesh's normals into a normal map on a low-resolution one
    Bake(commands::bake::BakeArgs),
    /// Join the films of tiles and sample ranges (render --tile/--crop/--samples) into one image
    Merge(commands::merge::MergeArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // No command is `raylab render` with clap's defaults (a derived `Default` would give 0
    // for the pass size and the checkpoint interval).
    let command = cli.command.unwrap_or_else(|| Cli::parse_from(["raylab", "render"]).command.expect("`render` parses"));
    let result = match command {
        Command::Render(a) => commands::render::run(&a),
        Command::Inspect(a) => commands::inspect::run(&a),
        Command::Gen(a) => commands::gen::run(&a),
        Command::Bench(a) => commands::bench::run(&a),
        Command::Trace(a) => commands::trace::run(&a),
        Command::Compare(a) => commands::compare::run(&a),
        Command::Converge(a) => commands::converge::run(&a),
        Command::Bake(a) => commands::bake::run(&a),
        Command::Merge(a) => commands::merge::run(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A render stopped by SIGINT/SIGTERM after saving its work: 130/143, as shells expect.
        Err(e) if e.downcast_ref::<commands::render::Interrupted>().is_some() => {
            let i = e.downcast_ref::<commands::render::Interrupted>().unwrap();
            eprintln!("raylab: error: {i}");
            ExitCode::from(i.code)
        }
        Err(e) => {
            eprintln!("raylab: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Where an output image goes unless `-o` says otherwise.
pub fn default_output() -> PathBuf {
    PathBuf::from("raylab.png")
}
