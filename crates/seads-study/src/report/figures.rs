//! The report's figures, per environment: skill coverage and task success over training (mean
//! of the variant's runs with a min–max band, the seed's Fig. S.15/S.16 style), and box plots of
//! solution and skill length per depth (Figs. S.5, S.6); whiskers at Tukey's 1.5 × IQR fences.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::{Result, StudyError};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::runs::{Group, RunData};
use crate::draw::{framed_legend, labelled_line, plot_err, png_and_svg, render_to, skill_colour};

/// A curve: x, mean, min, max.
type Band = Vec<(f64, f64, f64, f64)>;

/// The mean, min and max over the runs at each x-key present in every run; x is the mean of
/// the runs' x at that key (runs of a variant evaluate at the same epochs, a few environment
/// steps apart).
fn band(series: &[Vec<(u64, f64, f64)>]) -> Band {
    let mut by_key: BTreeMap<u64, Vec<(f64, f64)>> = BTreeMap::new();
    for s in series {
        for &(key, x, y) in s {
            by_key.entry(key).or_default().push((x, y));
        }
    }
    by_key
        .into_values()
        .filter(|v| v.len() == series.len())
        .map(|v| {
            let n = v.len() as f64;
            let x = v.iter().map(|p| p.0).sum::<f64>() / n;
            let ys = v.iter().map(|p| p.1);
            let mean = ys.clone().sum::<f64>() / n;
            let min = ys.clone().fold(f64::INFINITY, f64::min);
            let max = ys.fold(f64::NEG_INFINITY, f64::max);
            (x, mean, min, max)
        })
        .collect()
}

/// The corner of the plot where the legend hides the least: of the lower right, middle right and
/// upper left (in that order of preference), the one over the fewest drawn points (the means
/// and the bands' edges), each corner a box of 35 % of the width and 30 % of the height.
fn legend_corner(curves: &[(String, Band)], x_max: f64, y_max: f64) -> SeriesLabelPosition {
    let corners = [
        (SeriesLabelPosition::LowerRight, (0.65, 1.0), (0.0, 0.3)),
        (SeriesLabelPosition::MiddleRight, (0.65, 1.0), (0.35, 0.65)),
        (SeriesLabelPosition::UpperLeft, (0.0, 0.35), (0.7, 1.0)),
    ];
    let points: Vec<(f64, f64)> = curves
        .iter()
        .flat_map(|(_, band)| band.iter())
        .flat_map(|&(x, mean, min, max)| [(x, mean), (x, min), (x, max)])
        .map(|(x, y)| (x / x_max, y / y_max))
        .collect();
    let covered = |(x0, x1): (f64, f64), (y0, y1): (f64, f64)| {
        points
            .iter()
            .filter(|(x, y)| (x0..=x1).contains(x) && (y0..=y1).contains(y))
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, xs, ys)| covered(xs, ys))
        .map_or(SeriesLabelPosition::LowerRight, |c| c.0)
}

/// Draws one band per variant into `out`.
fn band_figure(
    out: &Path,
    title: &str,
    y_desc: &str,
    y_max: f64,
    curves: &[(String, Band)],
) -> Result<()> {
    render_to!(out, (900, 520), |area: &DrawingArea<_, Shift>| {
        let x_max = curves
            .iter()
            .flat_map(|(_, b)| b.iter().map(|p| p.0))
            .fold(1.0, f64::max);
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..x_max, 0.0..y_max)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("environment steps")
            .y_desc(y_desc)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(plot_err)?;
        for (i, (name, band)) in curves.iter().enumerate() {
            let colour = skill_colour(i);
            let mut outline: Vec<(f64, f64)> = band.iter().map(|p| (p.0, p.3)).collect();
            outline.extend(band.iter().rev().map(|p| (p.0, p.2)));
            chart
                .draw_series(std::iter::once(Polygon::new(
                    outline,
                    colour.mix(0.18).filled(),
                )))
                .map_err(plot_err)?;
            labelled_line(
                &mut chart,
                LineSeries::new(band.iter().map(|p| (p.0, p.1)), colour.stroke_width(2)),
                name,
                colour,
            )?;
        }
        framed_legend(&mut chart, legend_corner(curves, x_max, y_max))?;
        Ok::<(), StudyError>(())
    })
}

/// Coverage over training per environment; returns the files written.
pub fn coverage_figures(
    out: &Path,
    groups: &[Group<'_>],
    k_of: &dyn Fn(&Group<'_>) -> usize,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for env in envs(groups) {
        let mut curves = Vec::new();
        let mut k = 1;
        for g in groups.iter().filter(|g| g.env == env) {
            k = k.max(k_of(g));
            let series: Vec<Vec<(u64, f64, f64)>> = g
                .runs
                .iter()
                .map(|r| {
                    r.lines
                        .iter()
                        .filter_map(|m| Some((m.epoch, m.env_steps as f64, m.skill_coverage?)))
                        .collect()
                })
                .collect();
            // A baseline has no skills: no curve.
            let band = band(&series);
            if !band.is_empty() {
                curves.push((format!("{} (n = {})", g.variant, g.runs.len()), band));
            }
        }
        if curves.is_empty() {
            continue;
        }
        let title = format!("Skill coverage: {env} (mean, min–max band)");
        written.extend(png_and_svg(out, &format!("coverage-{env}"), &|p| {
            band_figure(
                p,
                &title,
                "distinct moves by the K skills",
                k as f64 + 0.5,
                &curves,
            )
        })?);
    }
    Ok(written)
}

/// The run score distribution of final skill coverage per environment (a performance profile,
/// Agarwal et al. 2021): for each threshold τ from 0 to K, the share of a variant's runs whose
/// final coverage exceeds τ, a step line per variant; returns the files written.
pub fn profile_figures(
    out: &Path,
    groups: &[Group<'_>],
    k_of: &dyn Fn(&Group<'_>) -> usize,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for env in envs(groups) {
        let mut k = 1;
        let mut profiles = Vec::new();
        for g in groups.iter().filter(|g| g.env == env) {
            let finals: Vec<f64> = g.runs.iter().filter_map(|r| r.final_coverage()).collect();
            if finals.is_empty() {
                continue;
            }
            k = k.max(k_of(g));
            profiles.push((format!("{} (n = {})", g.variant, finals.len()), finals));
        }
        if profiles.is_empty() {
            continue;
        }
        let x_max = k as f64;
        let title = format!("Run score distribution: {env}");
        written.extend(png_and_svg(
            out,
            &format!("profile-{env}"),
            &|p: &Path| -> Result<()> {
                render_to!(p, (900, 520), |area: &DrawingArea<_, Shift>| {
                    let mut chart = ChartBuilder::on(area)
                        .caption(&title, ("sans-serif", 20))
                        .margin(12)
                        .x_label_area_size(45)
                        .y_label_area_size(60)
                        .build_cartesian_2d(0.0..x_max, 0.0..1.05)
                        .map_err(plot_err)?;
                    chart
                        .configure_mesh()
                        .x_desc("final skill coverage τ (distinct moves)")
                        .y_desc("share of runs with coverage > τ")
                        .draw()
                        .map_err(plot_err)?;
                    for (i, (name, finals)) in profiles.iter().enumerate() {
                        let colour = skill_colour(i);
                        // A step at each run's value: the share holds until τ reaches it.
                        let mut steps: Vec<f64> = finals.clone();
                        steps.sort_by(f64::total_cmp);
                        let mut points = vec![(0.0, super::intervals::share_above(finals, 0.0))];
                        for &v in &steps {
                            let before = points.last().map_or(1.0, |p| p.1);
                            points.push((v, before));
                            points.push((v, super::intervals::share_above(finals, v)));
                        }
                        let last = points.last().map_or(0.0, |p| p.1);
                        points.push((x_max, last));
                        labelled_line(
                            &mut chart,
                            LineSeries::new(points, colour.stroke_width(2)),
                            name,
                            colour,
                        )?;
                    }
                    framed_legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
                    Ok::<(), StudyError>(())
                })
            },
        )?);
    }
    Ok(written)
}

/// A run's task success over training as (epoch, env steps, % solved): a baseline evaluates its
/// policy as it trains (`metrics.jsonl`); a SEADS run has what `seads evaluate --checkpoints`
/// added (with re-planning, depths pooled). Empty for a run not evaluated over training.
fn success_series(run: &RunData) -> Vec<(u64, f64, f64)> {
    let measured: Vec<(u64, f64, f64)> = run
        .lines
        .iter()
        .filter_map(|m| Some((m.epoch, m.env_steps as f64, 100.0 * m.mean_success?)))
        .collect();
    if !measured.is_empty() {
        return measured;
    }
    run.over_training
        .iter()
        .filter(|l| l.replan)
        .map(|l| {
            (
                l.epoch,
                l.env_steps as f64,
                100.0 * super::tables::solved_share(&l.results),
            )
        })
        .collect()
}

/// Which runs the success-over-training figures rest on, one line per environment and variant
/// that has any: "lightsout-cursor / seads: 1 of 5 runs". `None` when no run has such data.
pub fn success_note(groups: &[Group<'_>]) -> Option<String> {
    let lines: Vec<String> = groups
        .iter()
        .filter_map(|g| {
            let with = g
                .runs
                .iter()
                .filter(|r| !success_series(r).is_empty())
                .count();
            (with > 0)
                .then(|| format!("{} / {}: {with} of {} runs", g.env, g.variant, g.runs.len()))
        })
        .collect();
    (!lines.is_empty()).then(|| {
        format!(
            "Task success over training rests on the runs evaluated over training ({}).",
            lines.join("; ")
        )
    })
}

/// Task success over training (SEADS with re-planning, a baseline's policy; mean over the depths)
/// per environment, for the groups whose runs were evaluated over training (each curve over the
/// runs that were, its n in the legend); returns the files written.
pub fn success_figures(out: &Path, groups: &[Group<'_>]) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for env in envs(groups) {
        let mut curves = Vec::new();
        for g in groups.iter().filter(|g| g.env == env) {
            let series: Vec<Vec<(u64, f64, f64)>> = g
                .runs
                .iter()
                .map(|r| success_series(r))
                .filter(|s| !s.is_empty())
                .collect();
            let band = band(&series);
            if !band.is_empty() {
                curves.push((format!("{} (n = {})", g.variant, series.len()), band));
            }
        }
        if curves.is_empty() {
            continue;
        }
        let title = format!(
            "Task success over training: {env} (SEADS re-planning, baselines' policies; depths pooled)"
        );
        written.extend(png_and_svg(out, &format!("success-{env}"), &|p| {
            band_figure(p, &title, "test tasks solved (%)", 105.0, &curves)
        })?);
    }
    Ok(written)
}

/// Box plots of solution length and skill length per depth (with re-planning, solved tasks of
/// all runs of the variant), one figure per environment and variant; returns the files written.
pub fn length_figures(out: &Path, groups: &[Group<'_>]) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for g in groups {
        let mut per_depth: BTreeMap<usize, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
        for e in g.runs.iter().filter_map(|r| r.replan.as_ref()) {
            for r in e {
                let entry = per_depth.entry(r.depth).or_default();
                entry.0.extend(r.solution_steps.iter().map(|&s| s as f64));
                entry.1.extend(r.skill_steps.iter().map(|&s| s as f64));
            }
        }
        per_depth.retain(|_, (solutions, _)| !solutions.is_empty());
        if per_depth.is_empty() {
            continue;
        }
        let name = format!("lengths-{}-{}", g.env, g.variant);
        let title = format!("{} / {}", g.env, g.variant);
        written.extend(png_and_svg(out, &name, &|p| {
            box_figure(p, &title, &per_depth)
        })?);
    }
    Ok(written)
}

fn box_figure(
    out: &Path,
    title: &str,
    per_depth: &BTreeMap<usize, (Vec<f64>, Vec<f64>)>,
) -> Result<()> {
    render_to!(out, (1000, 450), |area: &DrawingArea<_, Shift>| {
        let panels = area.split_evenly((1, 2));
        let depths: Vec<u32> = per_depth.keys().map(|&d| d as u32).collect();
        let (lo, hi) = (depths[0], depths[depths.len() - 1]);
        for (panel, (label, pick)) in panels.iter().zip([
            ("solution length (manipulator steps)", 0usize),
            ("skill length (manipulator steps)", 1),
        ]) {
            let values =
                |v: &(Vec<f64>, Vec<f64>)| if pick == 0 { v.0.clone() } else { v.1.clone() };
            // Room for the whiskers (Tukey's 1.5 × IQR fences, as plotters draws them).
            let y_max = per_depth
                .values()
                .map(|v| {
                    let v = values(v);
                    let fence = Quartiles::new(&v).values()[4];
                    v.iter().fold(fence, |m, &x| m.max(x as f32))
                })
                .fold(1.0, f32::max)
                * 1.1;
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("{label}: {title}"), ("sans-serif", 15))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d((lo..hi).into_segmented(), 0f32..y_max)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("solution depth")
                .y_desc("steps")
                .draw()
                .map_err(plot_err)?;
            chart
                .draw_series(per_depth.iter().map(|(d, v)| {
                    let q = Quartiles::new(&values(v));
                    Boxplot::new_vertical(SegmentValue::CenterOf(*d as u32), &q)
                        .width(30)
                        .style(BLUE)
                }))
                .map_err(plot_err)?;
        }
        Ok::<(), StudyError>(())
    })
}

fn envs<'a>(groups: &'a [Group<'_>]) -> Vec<&'a str> {
    let mut envs: Vec<&str> = Vec::new();
    for g in groups {
        if !envs.contains(&g.env.as_str()) {
            envs.push(&g.env);
        }
    }
    envs
}

#[cfg(test)]
mod tests {
    use plotters::prelude::SeriesLabelPosition;

    use super::legend_corner;

    fn flat(y: f64) -> super::Band {
        (0..=10).map(|i| (i as f64 * 10.0, y, y, y)).collect()
    }

    #[test]
    fn the_legend_goes_where_no_curve_runs() {
        let name = String::new;
        // Curves near the top (coverage): the lower right is free.
        let high = [(name(), flat(24.0))];
        assert!(matches!(
            legend_corner(&high, 100.0, 25.0),
            SeriesLabelPosition::LowerRight
        ));
        // One curve at the top, one along the bottom (baselines' success): the middle right.
        let split = [(name(), flat(100.0)), (name(), flat(5.0))];
        assert!(matches!(
            legend_corner(&split, 100.0, 100.0),
            SeriesLabelPosition::MiddleRight
        ));
        // Curves at the bottom and the middle: the upper left.
        let low = [(name(), flat(5.0)), (name(), flat(50.0))];
        assert!(matches!(
            legend_corner(&low, 100.0, 100.0),
            SeriesLabelPosition::UpperLeft
        ));
    }
}
