//! Drawing with plotters: the embedded font, top views of scenes, end-effector paths, and a
//! helper that writes the same figure as PNG or SVG.

use std::sync::Once;

use crate::{Result, StudyError};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use seads_embodiment::{FieldView, Scene, Shape, SkillRun};

/// A chart in board coordinates.
pub type BoardChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws `line` into `chart` with a legend entry `name`: a short stroke of `colour`, the line's
/// colour.
pub fn labelled_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut BoardChart<'a, DB>,
    line: LineSeries<DB, (f64, f64)>,
    name: &str,
    colour: RGBColor,
) -> Result<()> {
    chart
        .draw_series(line)
        .map_err(plot_err)?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
    Ok(())
}

/// The legend of `chart`'s labelled series at `position`, framed on a light background.
pub fn framed_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut BoardChart<'a, DB>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .draw()
        .map_err(plot_err)
}

/// Registers DejaVu Sans as plotters' "sans-serif" (once per process).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The fonts are valid TTFs shipped by the `dejavu` crate; registration cannot fail.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
        let _ = plotters::style::register_font("sans-serif", FontStyle::Bold, dejavu::sans::bold());
    });
}

/// A plotters drawing error as a [`StudyError::Plot`].
pub fn plot_err<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> StudyError {
    StudyError::Plot(e.to_string())
}

/// Writes a figure to `$out` (PNG, or SVG by extension) of `$size` pixels: `$draw` is called
/// with the white drawing area and returns a `Result` whose error converts into the caller's.
/// (A macro, not a function: the two backends are different types.)
#[macro_export]
macro_rules! render_to {
    ($out:expr, $size:expr, $draw:expr) => {{
        let out: &std::path::Path = $out;
        $crate::draw::register_font();
        if out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
        {
            let area = plotters::prelude::SVGBackend::new(out, $size).into_drawing_area();
            area.fill(&plotters::prelude::WHITE)
                .map_err($crate::draw::plot_err)?;
            ($draw)(&area)?;
            area.present().map_err($crate::draw::plot_err)?;
        } else {
            let area = plotters::prelude::BitMapBackend::new(out, $size).into_drawing_area();
            area.fill(&plotters::prelude::WHITE)
                .map_err($crate::draw::plot_err)?;
            ($draw)(&area)?;
            area.present().map_err($crate::draw::plot_err)?;
        }
        Ok(())
    }};
}
pub use render_to;

/// Draws the figure `name` twice into `out`, as `name.png` and `name.svg`; returns both paths.
pub fn png_and_svg<E: Into<crate::BoxError>>(
    out: &std::path::Path,
    name: &str,
    draw: &dyn Fn(&std::path::Path) -> std::result::Result<(), E>,
) -> crate::Result<Vec<std::path::PathBuf>> {
    let mut written = Vec::new();
    for ext in ["png", "svg"] {
        let path = out.join(format!("{name}.{ext}"));
        draw(&path).map_err(|e| StudyError::file(format!("drawing {}", path.display()), e))?;
        written.push(path);
    }
    Ok(written)
}

/// Lit LightsOut field.
const LIT: RGBColor = RGBColor(245, 190, 40);
/// Unlit LightsOut field.
const UNLIT: RGBColor = RGBColor(70, 70, 80);
/// TileSwap tile.
const TILE: RGBColor = RGBColor(200, 215, 235);

/// A square view around `extent`, so that the board keeps its proportions.
fn square(extent: [f64; 4]) -> [f64; 4] {
    let [u0, v0, u1, v1] = extent;
    let half = (u1 - u0).max(v1 - v0) / 2.0;
    let (cu, cv) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
    [cu - half, cv - half, cu + half, cv + half]
}

/// Draws `scene` onto `area` under `title` (font size `font`); returns the chart so that
/// callers can draw more in board coordinates. `manipulator` draws the manipulator too.
pub fn draw_scene<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    scene: &Scene,
    title: &str,
    font: u32,
    manipulator: bool,
) -> Result<BoardChart<'a, DB>>
where
    DB::ErrorType: 'static,
{
    let [u0, v0, u1, v1] = square(scene.extent);
    // v grows downwards (row 0 on top), as on the board.
    let chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", font))
        .margin(6)
        .build_cartesian_2d(u0..u1, v1..v0)
        .map_err(plot_err)?;
    let plot = chart.plotting_area();
    for field in &scene.fields {
        let [a, b, c, d] = field.rect;
        // A field with neither light nor label is empty: the sliding puzzle's gap.
        let fill = match (field.lit, &field.label) {
            (Some(true), _) => LIT,
            (Some(false), _) => UNLIT,
            (None, Some(_)) => TILE,
            (None, None) => WHITE,
        };
        plot.draw(&Rectangle::new([(a, b), (c, d)], fill.filled()))
            .map_err(plot_err)?;
        plot.draw(&Rectangle::new([(a, b), (c, d)], BLACK.stroke_width(1)))
            .map_err(plot_err)?;
        if let Some(label) = &field.label {
            let pos = plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Center,
            );
            let style = TextStyle::from(("sans-serif", font + 4).into_font())
                .color(&BLACK)
                .pos(pos);
            plot.draw(&Text::new(
                label.clone(),
                ((a + c) / 2.0, (b + d) / 2.0),
                style,
            ))
            .map_err(plot_err)?;
        }
    }
    for &[u, v] in &scene.pivots {
        plot.draw(&Circle::new((u, v), 3, RGBColor(120, 120, 120).filled()))
            .map_err(plot_err)?;
    }
    if manipulator {
        let arm = RGBColor(30, 60, 160);
        for shape in &scene.shapes {
            match *shape {
                Shape::Segment { from, to } => plot.draw(&PathElement::new(
                    vec![(from[0], from[1]), (to[0], to[1])],
                    arm.stroke_width(5),
                )),
                Shape::Joint { at } => plot.draw(&Circle::new((at[0], at[1]), 5, arm.filled())),
                Shape::Marker { at } => {
                    plot.draw(&Cross::new((at[0], at[1]), 9, RED.stroke_width(4)))
                }
            }
            .map_err(plot_err)?;
        }
    }
    Ok(chart)
}

/// A colour per skill, distinguishable for up to ~30 skills.
pub fn skill_colour(k: usize) -> RGBColor {
    let (r, g, b) = HSLColor(((k * 7) % 30) as f64 / 30.0, 0.75, 0.42).rgb();
    RGBColor(r, g, b)
}

/// Draws end-effector paths in board coordinates, each in the colour of its key: a line, a
/// hollow circle where it started, a filled dot at a push that moved the board and a cross at a
/// push that did not.
pub fn draw_paths<DB: DrawingBackend>(
    chart: &mut BoardChart<'_, DB>,
    runs: &[(usize, &SkillRun)],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let plot = chart.plotting_area();
    for &(key, run) in runs {
        let colour = skill_colour(key);
        let points: Vec<(f64, f64)> = run.path.iter().map(|p| (p[0], p[1])).collect();
        plot.draw(&PathElement::new(points.clone(), colour.stroke_width(2)))
            .map_err(plot_err)?;
        plot.draw(&Circle::new(points[0], 4, colour.stroke_width(2)))
            .map_err(plot_err)?;
        for (i, &step) in run.pushes.iter().enumerate() {
            let moved = i + 1 == run.pushes.len() && run.outcome.moved();
            if moved {
                plot.draw(&Circle::new(points[step], 6, colour.filled()))
                    .map_err(plot_err)?;
            } else {
                plot.draw(&Cross::new(points[step], 5, colour.stroke_width(2)))
                    .map_err(plot_err)?;
            }
        }
    }
    Ok(())
}

/// Renders a scene to a PNG or SVG file (by extension).
pub fn render_scene(scene: &Scene, title: &str, out: &std::path::Path) -> Result<()> {
    let flat = scene
        .fields
        .iter()
        .all(|f| (f.height - scene.fields[0].height).abs() < 1e-9);
    if flat {
        return render_to!(out, (600, 640), |area: &DrawingArea<_, Shift>| draw_scene(
            area, scene, title, 18, true
        )
        .map(|_| ()));
    }
    // Fields of different heights (LightsOut3DJaco): the top view and, below it, a side view
    // of the cross-section through the middle row, so that raised and recessed fields show.
    render_to!(out, (600, 880), |area: &DrawingArea<_, Shift>| {
        let (top, side) = area.split_vertically(640);
        draw_scene(&top, scene, title, 18, true)?;
        draw_section(&side, scene)
    })
}

/// The side view of the fields whose centre lies in the middle row, heights in centimetres.
fn draw_section<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, scene: &Scene) -> Result<()> {
    let centre_v = |f: &FieldView| (f.rect[1] + f.rect[3]) / 2.0;
    let middle = scene
        .fields
        .iter()
        .map(centre_v)
        .min_by(|a, b| (a - 0.5).abs().total_cmp(&(b - 0.5).abs()))
        .unwrap_or(0.5);
    let row: Vec<&FieldView> = scene
        .fields
        .iter()
        .filter(|f| (centre_v(f) - middle).abs() < 1e-6)
        .collect();
    let top = row.iter().map(|f| f.height * 100.0).fold(0.0, f64::max) * 1.25 + 0.5;
    let mut chart = ChartBuilder::on(area)
        .caption("side view: the middle row's fields", ("sans-serif", 15))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..1.0, 0.0..top)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_desc("position across the board")
        .y_desc("height (cm)")
        .draw()
        .map_err(plot_err)?;
    chart
        .draw_series(row.iter().map(|f| {
            let colour = if f.lit == Some(true) { LIT } else { UNLIT };
            Rectangle::new(
                [
                    (f.rect[0] + 0.005, 0.0),
                    (f.rect[2] - 0.005, f.height * 100.0),
                ],
                colour.filled(),
            )
        }))
        .map_err(plot_err)?;
    Ok(())
}

/// The board before solving with the paths of the executed skills (`seads solve --render`).
pub fn render_solution(
    before: &Scene,
    runs: &[SkillRun],
    title: &str,
    out: &std::path::Path,
) -> Result<()> {
    let keyed: Vec<(usize, &SkillRun)> = runs.iter().enumerate().collect();
    render_to!(out, (600, 640), |area: &DrawingArea<_, Shift>| {
        let mut chart = draw_scene(area, before, title, 18, false)?;
        draw_paths(&mut chart, &keyed)
    })
}
