//! The figures of one run (`seads plot`): skill coverage over training, task success per depth
//! with and without re-planning, skill trajectories (seed Fig. S.2–S.4) and push points per
//! skill (Fig. S.1).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use seads_embodiment::{Environment, SkillPolicy, SkillRun, execute_skill};
use seads_planner::DepthResult;
use seads_run::COVERAGE_SEED;

use crate::draw::{
    draw_paths, draw_scene, framed_legend, labelled_line, plot_err, render_to, skill_colour,
};
use crate::{Result, StudyError};

/// The trajectories and push points of every skill, executed in `env` from the 20 coverage
/// initialisations.
pub fn skill_figures<E: Into<crate::BoxError>>(
    env: &mut dyn Environment,
    policy: &dyn SkillPolicy,
    title: &str,
    mut both: impl FnMut(&str, &dyn Fn(&Path) -> Result<()>) -> std::result::Result<(), E>,
) -> Result<()> {
    let runs = skill_runs(env, policy)?;
    env.seed(COVERAGE_SEED);
    env.reset()
        .map_err(|e| StudyError::file("resetting the environment", e))?;
    let scene = env.scene();
    let mut both = |name: &str, draw: &dyn Fn(&Path) -> Result<()>| {
        both(name, draw).map_err(|e| StudyError::file(format!("drawing {name}"), e))
    };
    both("trajectories", &|p| {
        trajectories_figure(p, &scene, &runs, title)
    })?;
    both("pushes", &|p| pushes_figure(p, &scene, &runs, title))
}

/// Every skill executed from the 20 coverage initialisations of `env` (for registry
/// environments, test boards under the training reset distribution): `runs[k]` holds skill k's 20
/// executions.
pub fn skill_runs(
    env: &mut dyn Environment,
    policy: &dyn SkillPolicy,
) -> Result<Vec<Vec<SkillRun>>> {
    let k = policy.num_skills();
    (0..k)
        .map(|skill| {
            (0..20)
                .map(|i| {
                    env.seed(COVERAGE_SEED + i);
                    env.reset()
                        .map_err(|e| StudyError::file("resetting the environment", e))?;
                    execute_skill(env, policy, skill)
                        .map_err(|e| StudyError::file("executing a skill", e))
                })
                .collect()
        })
        .collect()
}

/// Skill coverage over training (from the run's metrics), of `k` skills.
pub fn coverage_figure(
    out: &Path,
    metrics: &[seads_run::Metrics],
    k: usize,
    title: &str,
) -> Result<()> {
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
        Ok::<(), StudyError>(())
    })
}

/// Task success per depth, with and without re-planning.
pub fn success_figure(
    out: &Path,
    evaluations: &[(bool, Vec<DepthResult>)],
    title: &str,
) -> Result<()> {
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
                .map(|r| (r.depth as f64 + dx, 100.0 * r.success_rate()))
                .collect();
            labelled_line(
                &mut chart,
                LineSeries::new(points, colour.stroke_width(2)).point_size(4),
                label,
                colour,
            )?;
        }
        framed_legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
        Ok::<(), StudyError>(())
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

/// Each skill's trajectories over the board, one panel per skill.
pub fn trajectories_figure(
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
            Ok::<(), StudyError>(())
        }
    )
}

/// Where each skill pushed, over the board.
pub fn pushes_figure(
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
        Ok::<(), StudyError>(())
    })
}
