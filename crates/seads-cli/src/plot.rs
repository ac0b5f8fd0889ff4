//! `seads plot`: the figures of a run — skill coverage over training, task success per depth
//! with and without re-planning, skill trajectories (seed Fig. S.2–S.4) and push points per
//! skill (Fig. S.1).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use plotters::coord::Shift;
use plotters::prelude::*;
use seads_embodiment::{EnvConfig, Environment, SkillRun, execute_skill};
use seads_games::Split;
use seads_planner::DepthResult;
use seads_rl::{Agent, AgentPolicy, COVERAGE_SEED, find_checkpoint, read_metrics};

use crate::envs::build_env;
use crate::plan::{load_agent, run_evaluation};
use seads_planner::{EvaluationKind, Protocol, STANDARD_DEPTHS, SearchLimits, TaskSet};
use seads_study::draw::{draw_paths, draw_scene, plot_err, render_to, skill_colour};
use seads_study::evaluation::read_evaluation;

/// Arguments of `seads plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Run directory of a trained agent.
    #[arg(long)]
    run: PathBuf,
    /// Folder for the figures (PNG and SVG of each).
    #[arg(long)]
    out: PathBuf,
    /// Use the checkpoint of this epoch instead of the latest.
    #[arg(long)]
    checkpoint: Option<u64>,
    /// Boards per depth when an evaluation must be run first (saved evaluations are reused).
    #[arg(long, default_value_t = 20)]
    boards: usize,
    /// Time limit per search in such an evaluation, seconds.
    #[arg(long, default_value_t = 60.0, value_parser = crate::positive_finite)]
    timeout: f64,
}

/// `seads plot`: writes every figure of the run into `out`; returns the files written.
pub fn plot(args: PlotArgs) -> Result<()> {
    // Plotting may evaluate the run and save that evaluation into it.
    seads_rl::load_config(&args.run)
        .with_context(|| format!("loading run {}", args.run.display()))?;
    let _lock = crate::lock_run(&args.run)?;
    let written = write_figures(
        &args.run,
        &args.out,
        args.checkpoint,
        args.boards,
        args.timeout,
        false,
    )?;
    for path in written {
        outln!("wrote {}", path.display());
    }
    Ok(())
}

/// Writes the figures of the run in `run` into `out`.
pub fn write_figures(
    run: &Path,
    out: &Path,
    checkpoint: Option<u64>,
    boards: usize,
    timeout: f64,
    quiet: bool,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut written = Vec::new();
    let mut both = |name: &str, f: &dyn Fn(&Path) -> Result<()>| -> Result<()> {
        written.extend(seads_study::draw::png_and_svg(out, name, f)?);
        Ok(())
    };
    let metrics = read_metrics(run)?;
    let config = seads_rl::load_config(run)?;
    let title = format!("{} (seed {})", config.env, config.seed);
    if let Some(mut twin) = crate::uarm::twin_for_figures(&config)? {
        // A robot run: its skills are shown on the twin, and its success is what `seads uarm
        // train` measured (with re-planning only).
        let spec = twin.spec().clone();
        let agent = Agent::load_for(config, spec, &find_checkpoint(run, checkpoint)?)?;
        let k = agent.policy_skills();
        both("coverage", &|p| coverage_figure(p, &metrics, k, &title))?;
        let file = EvaluationKind::Replan.results_file(&STANDARD_DEPTHS, None);
        match read_evaluation(&run.join(&file)).map_err(crate::study_error)? {
            Some(record) if record.checkpoint.is_some_and(|c| c.epoch == agent.epoch) => {
                let replan = [(true, record.results)];
                both("success", &|p| success_figure(p, &replan, &title))?;
            }
            Some(_) if !quiet => eprintln!(
                "seads: {file} is not an evaluation of epoch {}: no success figure \
                 (`seads uarm evaluate` makes one)",
                agent.epoch
            ),
            _ => {}
        }
        if !quiet {
            eprintln!(
                "seads: {} is a robot run ({}): its skills are drawn as the twin executes them",
                run.display(),
                agent.config.env
            );
        }
        return skill_figures(&mut twin, &agent, &title, both).map(|()| written);
    }
    let mut agent = load_agent(run, checkpoint)?;
    let k = agent.policy_skills();
    both("coverage", &|p| coverage_figure(p, &metrics, k, &title))?;
    if agent.model.is_some() {
        let evaluations = evaluations(&mut agent, run, boards, timeout, quiet)?;
        both("success", &|p| success_figure(p, &evaluations, &title))?;
    } else if !quiet {
        eprintln!(
            "seads: {} is a VIC run: its skill discriminator cannot plan, so there is no task-success figure",
            run.display()
        );
    }
    let mut env = build_env(
        &agent.config.env,
        &EnvConfig {
            reset_split: Split::Test,
            ..agent.config.env_config.clone()
        },
    )?;
    skill_figures(env.as_mut(), &agent, &title, both)?;
    Ok(written)
}

/// The trajectories and push points of every skill, executed in `env` from the 20 coverage
/// initialisations.
fn skill_figures(
    env: &mut dyn Environment,
    agent: &Agent,
    title: &str,
    mut both: impl FnMut(&str, &dyn Fn(&Path) -> Result<()>) -> Result<()>,
) -> Result<()> {
    let runs = skill_runs(env, &agent.policy)?;
    env.seed(COVERAGE_SEED);
    env.reset()?;
    let scene = env.scene();
    both("trajectories", &|p| {
        trajectories_figure(p, &scene, &runs, title)
    })?;
    both("pushes", &|p| pushes_figure(p, &scene, &runs, title))
}

trait PolicySkills {
    fn policy_skills(&self) -> usize;
}

impl PolicySkills for Agent {
    fn policy_skills(&self) -> usize {
        seads_embodiment::SkillPolicy::num_skills(&self.policy)
    }
}

/// The run's evaluations of the agent's checkpoint with and without re-planning: the saved ones
/// where they name that checkpoint (`evaluation-replan.json`, `evaluation-plan-once.json`),
/// otherwise evaluated now (an evaluation of an earlier checkpoint, or one that does not say
/// which it evaluated, is never shown for this one).
fn evaluations(
    agent: &mut Agent,
    run: &Path,
    boards: usize,
    timeout: f64,
    quiet: bool,
) -> Result<[(bool, Vec<DepthResult>); 2]> {
    let mut load = |replan: bool| -> Result<Vec<DepthResult>> {
        let kind = EvaluationKind::planning(replan);
        let saved = read_evaluation(&run.join(kind.results_file(&STANDARD_DEPTHS, None)))
            .map_err(crate::study_error)?;
        if let Some(record) = saved
            && record.checkpoint.is_some_and(|c| c.epoch == agent.epoch)
        {
            return Ok(record.results);
        }
        let protocol = Protocol {
            kind,
            tasks: TaskSet::standard(boards),
            limits: Some(SearchLimits {
                timeout_s: timeout,
                max_expanded: None,
            }),
        };
        Ok(run_evaluation(agent, run, &protocol, quiet)?.results)
    };
    Ok([(true, load(true)?), (false, load(false)?)])
}

/// Every skill executed from the 20 coverage initialisations of `env` (for registry
/// environments, test boards under the training reset distribution): `runs[k]` holds skill k's 20
/// executions.
fn skill_runs(env: &mut dyn Environment, policy: &AgentPolicy) -> Result<Vec<Vec<SkillRun>>> {
    let k = seads_embodiment::SkillPolicy::num_skills(policy);
    (0..k)
        .map(|skill| {
            (0..20)
                .map(|i| {
                    env.seed(COVERAGE_SEED + i);
                    env.reset()?;
                    Ok(execute_skill(env, policy, skill)?)
                })
                .collect()
        })
        .collect()
}

fn coverage_figure(out: &Path, metrics: &[seads_rl::Metrics], k: usize, title: &str) -> Result<()> {
    render_to!(out, (800, 500), |area: &DrawingArea<_, Shift>| {
        let max_steps = metrics
            .iter()
            .map(|m| m.env_steps)
            .max()
            .unwrap_or(1)
            .max(1) as f64;
        let mut chart = ChartBuilder::on(area)
            .caption(format!("Skill coverage: {title}"), ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..max_steps, 0.0..(k as f64 + 0.5))
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("environment steps")
            .y_desc("distinct game moves by the K skills")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(LineSeries::new(
                [(0.0, k as f64), (max_steps, k as f64)],
                RED.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(format!("all {k} skills"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        let points: Vec<(f64, f64)> = metrics
            .iter()
            .map(|m| (m.env_steps as f64, m.skill_coverage))
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), BLUE.stroke_width(2)).point_size(3))
            .map_err(plot_err)?
            .label("skill coverage (20 test initialisations)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .draw()
            .map_err(plot_err)?;
        anyhow::Ok(())
    })
}

fn success_figure(out: &Path, evaluations: &[(bool, Vec<DepthResult>)], title: &str) -> Result<()> {
    render_to!(out, (800, 500), |area: &DrawingArea<_, Shift>| {
        let max_depth = evaluations
            .iter()
            .flat_map(|(_, r)| r.iter().map(|d| d.depth))
            .max()
            .unwrap_or(5) as f64;
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("Task success on test boards: {title}"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0.5..max_depth + 0.5, 0.0..105.0)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("solution depth of the board")
            .y_desc("tasks solved (%)")
            .x_labels(max_depth as usize)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(plot_err)?;
        for (replan, results) in evaluations {
            let colour = if *replan { BLUE } else { RED };
            let label = if *replan {
                "with re-planning"
            } else {
                "plan once"
            };
            // A small horizontal offset keeps both curves visible where they coincide.
            let dx = if *replan { -0.04 } else { 0.04 };
            let points: Vec<(f64, f64)> = results
                .iter()
                .map(|r| {
                    (
                        r.depth as f64 + dx,
                        100.0 * r.solved as f64 / r.tasks.max(1) as f64,
                    )
                })
                .collect();
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)).point_size(4))
                .map_err(plot_err)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .draw()
            .map_err(plot_err)?;
        anyhow::Ok(())
    })
}

/// The move most runs of a skill made, and how many made it.
fn dominant_move(runs: &[SkillRun]) -> Option<(usize, usize)> {
    let mut counts = std::collections::BTreeMap::new();
    for r in runs {
        if let Some(m) = r.outcome.game_move() {
            *counts.entry(m).or_insert(0) += 1;
        }
    }
    counts
        .into_iter()
        .max_by_key(|&(m, c)| (c, std::cmp::Reverse(m)))
}

fn trajectories_figure(
    out: &Path,
    scene: &seads_embodiment::Scene,
    runs: &[Vec<SkillRun>],
    title: &str,
) -> Result<()> {
    let k = runs.len();
    let cols = (k as f64).sqrt().ceil() as usize;
    let rows = k.div_ceil(cols);
    render_to!(
        out,
        (cols as u32 * 260, rows as u32 * 270 + 40),
        |area: &DrawingArea<_, Shift>| {
            let area = area.titled(
            &format!("Skill trajectories from 20 test initialisations: {title} (filled dot: push that moved the board, cross: push without effect)"),
            ("sans-serif", 16),
        ).map_err(plot_err)?;
            for (skill, panel) in area.split_evenly((rows, cols)).iter().enumerate().take(k) {
                // A frame per panel: the view reaches beyond the board, so without it a caption
                // stands nearer to the board above it than to its own.
                let (w, h) = panel.dim_in_pixel();
                panel
                    .draw(&Rectangle::new(
                        [(1, 1), (w as i32 - 2, h as i32 - 2)],
                        RGBColor(190, 190, 190).stroke_width(1),
                    ))
                    .map_err(plot_err)?;
                let caption = match dominant_move(&runs[skill]) {
                    Some((m, c)) => format!("skill {skill}: move {m} ({c}/20)"),
                    None => format!("skill {skill}: no move"),
                };
                let mut chart = draw_scene(panel, scene, &caption, 13, false)?;
                let keyed: Vec<(usize, &SkillRun)> =
                    runs[skill].iter().map(|r| (skill, r)).collect();
                draw_paths(&mut chart, &keyed)?;
            }
            anyhow::Ok(())
        }
    )
}

fn pushes_figure(
    out: &Path,
    scene: &seads_embodiment::Scene,
    runs: &[Vec<SkillRun>],
    title: &str,
) -> Result<()> {
    render_to!(out, (700, 740), |area: &DrawingArea<_, Shift>| {
        let chart = draw_scene(
            area,
            scene,
            &format!("Final pushes per skill (colour = skill): {title}"),
            16,
            false,
        )?;
        let plot = chart.plotting_area();
        for (skill, runs) in runs.iter().enumerate() {
            for r in runs {
                if let Some(&step) = r.pushes.last() {
                    let at = (r.path[step][0], r.path[step][1]);
                    let colour = skill_colour(skill);
                    if r.outcome.moved() {
                        plot.draw(&Circle::new(at, 5, colour.filled()))
                            .map_err(plot_err)?;
                    } else {
                        plot.draw(&Cross::new(at, 5, colour.stroke_width(2)))
                            .map_err(plot_err)?;
                    }
                }
            }
        }
        anyhow::Ok(())
    })
}
