//! `walker gait`: find the periodic gait of a scene and its stability.
//!
//! At the scene's default values, Newton from its guess; elsewhere the longer-period of that
//! and the defaults' gait followed to the requested values ([`sim::analysis::homotopy::nominal_gait`]), so the
//! long-period gait comes back wherever its branch reaches (`walker gaits` lists them all).

use super::{print_json, shown};
use crate::animation::{self, timeline, Animation};
use crate::export;
use crate::figures;
use crate::gait_text::GaitFigures;
use crate::options::Common;
use crate::output;
use crate::search_progress;
use anyhow::Result;
use clap::Args;
use sim::analysis::homotopy::GaitSource;
use sim::report::{AnkleExtension, GaitOutcome, GaitReport};
use sim::stride::walk::WalkRequest;
use std::io::Write;
use std::process::ExitCode;

/// Options of `walker gait`.
#[derive(Args)]
pub struct GaitArgs {
    #[command(flatten)]
    pub common: Common,
    /// Write figures (eigenvalues, joint angles over a stride) into this folder, each as SVG,
    /// PNG and PDF.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<std::path::PathBuf>,
    /// Write a self-contained HTML page that plays strides of the gait in 3D
    /// (docs/animation.md).
    #[arg(long, value_name = "FILE.html")]
    pub animate: Option<std::path::PathBuf>,
}

/// Strides of the gait an animation shows (two of each leg for a mirrored walker).
const ANIMATED_STRIDES: usize = 4;

/// Runs `walker gait`: exit code 1 if no gait is found.
pub fn run(args: GaitArgs) -> Result<ExitCode> {
    let GaitArgs {
        common,
        plot,
        animate,
    } = args;
    let scene = common.scene()?;
    let setup = common.setup(&scene)?;
    // The figures' folder before the gait search: a path that cannot be used fails at once.
    if let Some(dir) = &plot {
        output::create_dir("--plot", dir)?;
    }
    let animation = animation::open(animate.as_deref(), ANIMATED_STRIDES)?;
    let walker = &setup.walker;
    let sourced = search_progress::rule_gait(&common, &common.setup_for(), &scene)?;
    let source = sourced.as_ref().ok().map(|(_, s)| *s);
    let result = sourced.map(|(g, _)| g);
    let (mut report, figures_stride) =
        GaitReport::of_setup(&setup, &scene, &result, plot.is_some());
    report.gait_source = source;
    if let (Some(dir), Ok(g)) = (&plot, &result) {
        let eig = figures::eigenvalues(&scene, walker, g);
        export::write_figure("--plot", dir, "eigenvalues", &eig.to_svg(720.0, 560.0))?;
        let (samples, events) = figures_stride.as_ref().map_or((&[][..], &[][..]), |r| {
            (r.trajectory.as_slice(), r.event_states.as_slice())
        });
        let ang = figures::joint_angles(&scene, walker, samples, events);
        export::write_figure("--plot", dir, "joint_angles", &ang.to_svg(860.0, 480.0))?;
    }
    match (animation, &result) {
        (Some(file), Ok(g)) => {
            // Strides of the limit cycle: a walk from its fixed point.
            let (q, qd) = walker.unpack(&g.fixed_point);
            let request = WalkRequest::new(&setup.settings, ANIMATED_STRIDES)
                .recording(true)
                .path_interval(crate::animation::PATH_SAMPLE_INTERVAL_S);
            let walk = sim::stride::walk::walk(walker, &q, &qd, request);
            file.write(&Animation {
                scene: &scene,
                walker,
                walk: &walk,
                command: "gait",
                events: timeline::walk_events(&walk),
                firmware: false,
                emergency_stop_sent_s: None,
            })?;
        }
        (Some(file), Err(_)) => file.discard(),
        (None, _) => {}
    }
    if common.json {
        print_json(&report)?;
    } else {
        output::text(|out| print_text(out, &report))?;
    }
    Ok(if result.is_ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn print_text(out: &mut dyn Write, r: &GaitReport) -> std::io::Result<()> {
    writeln!(out, "scene: {}", r.scene)?;
    let g = match &r.outcome {
        GaitOutcome::NotFound(e) => {
            return writeln!(out, "no gait found: {}", e.error);
        }
        GaitOutcome::Found(g) => g,
    };
    writeln!(out, "fixed point (just after heel strike):")?;
    for (k, v) in &g.fixed_point.0 {
        writeln!(out, "    {k:<28} {:>20.12}", shown(*v))?;
    }
    writeln!(out, "eigenvalues of the stride Jacobian:")?;
    for [re, im] in &g.eigenvalues {
        let (re, im) = (shown(*re), shown(*im));
        writeln!(
            out,
            "    {re:>14.8} {im:>+14.8}i   |λ| = {:.8}",
            re.hypot(im)
        )?;
    }
    writeln!(
        out,
        "max |λ| = {:.8} ({}), {} Newton iterations",
        shown(g.max_abs_eigenvalue),
        if g.stable { "stable" } else { "unstable" },
        g.newton_iterations,
    )?;
    GaitFigures::of_found(g).write(out, "")?;
    if let Some(x) = &g.ankle_extension {
        print_ankle_extension(out, x)?;
    }
    match r.gait_source {
        Some(s @ GaitSource::ContinuedFromDefaults) => writeln!(
            out,
            "gait: {} (the scene's nominal branch); `walker gaits` lists every period-1 gait",
            s.describe()
        ),
        Some(s @ GaitSource::Guess) => writeln!(
            out,
            "gait: {} (the defaults' gait was not followed this far, or its period is \
             shorter); `walker gaits` lists every period-1 gait",
            s.describe()
        ),
        _ => Ok(()),
    }
}

/// The `ankle extension:` line of the text output.
fn print_ankle_extension(out: &mut dyn Write, x: &AnkleExtension) -> std::io::Result<()> {
    match x.engaged_at_s {
        Some(t0) => writeln!(
            out,
            "ankle extension: string engaged at {:.6} s, released at {:.6} s: {:.6} s of the \
             {:.6} s profile ({:.1} %); ankle at release {:.6} rad of {:.6} rad ({:.1} % of \
             the extension)",
            shown(t0),
            shown(x.released_at_s),
            shown(x.released_at_s - t0),
            shown(x.profile_duration_s),
            100.0 * shown(x.profile_fraction_completed),
            shown(x.angle_at_release_rad),
            shown(x.final_angle_rad),
            100.0 * shown(x.angle_fraction_completed),
        ),
        None => writeln!(
            out,
            "ankle extension: the string did not engage; ankle at heel strike {:.6} rad",
            shown(x.angle_at_release_rad),
        ),
    }
}
