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
    /// Allow images, meshes and files that need more memory than this machine (or job, or RAYLAB_MEMORY_LIMIT) has; they are refused otherwise
    #[arg(long, global = true)]
    allow_large: bool,
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
    /// Measure leaks and self-intersections of every structure and primitive kind at scales 1e-10..1e12
    Robustness(commands::robustness::RobustnessArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    raylab_render::memory_guard::allow_large(cli.allow_large);
    let result = match command_of(cli) {
        Command::Render(a) => commands::render::run(&a),
        Command::Inspect(a) => commands::inspect::run(&a),
        Command::Gen(a) => commands::gen::run(&a),
        Command::Bench(a) => commands::bench::run(&a),
        Command::Trace(a) => commands::trace::run(&a),
        Command::Compare(a) => commands::compare::run(&a),
        Command::Converge(a) => commands::converge::run(&a),
        Command::Bake(a) => commands::bake::run(&a),
        Command::Merge(a) => commands::merge::run(&a),
        Command::Robustness(a) => commands::robustness::run(&a),
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

/// The command to run: none is `raylab render` with clap's defaults (a derived `Default`
/// would give 0 for the pass size and the checkpoint interval).
fn command_of(cli: Cli) -> Command {
    cli.command.unwrap_or_else(|| Cli::parse_from(["raylab", "render"]).command.expect("`render` parses"))
}

/// Where an output image goes unless `-o` says otherwise.
pub fn default_output() -> PathBuf {
    PathBuf::from("raylab.png")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The README's first command, `raylab` alone, once panicked: its options were a derived
    /// `Default` with a pass size of 0. It must be exactly `raylab render`.
    #[test]
    fn no_command_is_render_with_its_defaults() {
        let Command::Render(bare) = command_of(Cli::parse_from(["raylab"])) else { panic!("not render") };
        let Some(Command::Render(render)) = Cli::parse_from(["raylab", "render"]).command else { panic!("not render") };
        assert_eq!(format!("{bare:?}"), format!("{render:?}"));
        assert_eq!(bare.pass_spp, raylab_render::film::DEFAULT_PASS_SAMPLES);
    }
}
