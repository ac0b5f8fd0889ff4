//! Drawing with plotters: the embedded font and top views of environment scenes.

use std::path::Path;
use std::sync::Once;

use anyhow::{Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use seads_embodiment::{Scene, Shape};

/// Registers DejaVu Sans as plotters' "sans-serif" (once per process).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a valid TTF shipped by the `dejavu` crate; registration cannot fail.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
        let _ = plotters::style::register_font("sans-serif", FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Lit LightsOut field.
pub const LIT: RGBColor = RGBColor(245, 190, 40);
/// Unlit LightsOut field.
pub const UNLIT: RGBColor = RGBColor(70, 70, 80);
/// TileSwap tile.
pub const TILE: RGBColor = RGBColor(200, 215, 235);

/// Draws `scene` onto `area` with `title` on top; returns the chart's coordinate mapping so that
/// callers can draw more (trajectories) in board coordinates.
pub fn draw_scene<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    scene: &Scene,
    title: &str,
) -> Result<
    ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
>
where
    DB::ErrorType: 'static,
{
    register_font();
    // A square view, so that the board keeps its proportions.
    let [u0, v0, u1, v1] = scene.extent;
    let half = (u1 - u0).max(v1 - v0) / 2.0;
    let (cu, cv) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
    let (u0, v0, u1, v1) = (cu - half, cv - half, cu + half, cv + half);
    let chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        // v grows downwards (row 0 on top), as on the board.
        .build_cartesian_2d(u0..u1, v1..v0)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let plot = chart.plotting_area();
    for field in &scene.fields {
        let [a, b, c, d] = field.rect;
        let fill = match field.lit {
            Some(true) => LIT,
            Some(false) => UNLIT,
            None => TILE,
        };
        plot.draw(&Rectangle::new([(a, b), (c, d)], fill.filled()))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        plot.draw(&Rectangle::new([(a, b), (c, d)], BLACK.stroke_width(1)))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        if let Some(label) = &field.label {
            let style = TextStyle::from(("sans-serif", 22).into_font())
                .color(&BLACK)
                .pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Center,
                ));
            plot.draw(&Text::new(
                label.clone(),
                ((a + c) / 2.0, (b + d) / 2.0),
                style,
            ))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
    }
    for &[u, v] in &scene.pivots {
        plot.draw(&Circle::new((u, v), 3, RGBColor(120, 120, 120).filled()))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let arm = RGBColor(30, 60, 160);
    for shape in &scene.shapes {
        let result = match *shape {
            Shape::Segment { from, to } => plot.draw(&PathElement::new(
                vec![(from[0], from[1]), (to[0], to[1])],
                arm.stroke_width(5),
            )),
            Shape::Joint { at } => plot.draw(&Circle::new((at[0], at[1]), 5, arm.filled())),
            Shape::Marker { at } => plot.draw(&Cross::new((at[0], at[1]), 9, RED.stroke_width(4))),
        };
        result.map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    Ok(chart)
}

/// Renders a scene to a PNG or SVG file (by extension).
pub fn render_scene(scene: &Scene, title: &str, out: &Path) -> Result<()> {
    let svg = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if svg {
        let area = SVGBackend::new(out, (600, 640)).into_drawing_area();
        area.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        draw_scene(&area, scene, title)?;
        area.present()
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("writing {}", out.display()))?;
    } else {
        let area = BitMapBackend::new(out, (600, 640)).into_drawing_area();
        area.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        draw_scene(&area, scene, title)?;
        area.present()
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("writing {}", out.display()))?;
    }
    Ok(())
}
