//! Horizontal bar charts: one labelled row per bar with its note, whiskers, dashed guides.

use super::axis::AxisCoord;
use super::{centred_lines, failed, font, format_tick, text_width_px, wrap, AxisSpec, Scale};
use super::{GRID, LABEL_PX, TITLE_PX};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One bar of a [`BarChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// Row label, left of the bars.
    pub label: String,
    /// Length of the bar.
    pub value: f64,
    /// Second value drawn as a thinner bar below (before/after charts).
    pub second: Option<f64>,
    /// Interval drawn as a whisker across the bar (uncertainty of the value).
    pub whisker: Option<[f64; 2]>,
    /// Text right of the bars.
    pub note: String,
    /// Drawn in the highlight colour.
    pub highlight: bool,
}

/// A horizontal bar chart: one labelled row per bar, dashed guide lines, an optional legend for
/// the first and second bars.
#[derive(Debug, Clone, PartialEq)]
pub struct BarChart {
    /// Title (broken into lines if wider than the image).
    pub title: String,
    /// The value axis; its label is broken into lines under the axis.
    pub axis: AxisSpec,
    pub bars: Vec<Bar>,
    /// Values marked by dashed vertical lines (a threshold).
    pub guides: Vec<f64>,
    /// Legend of the first and the second bars.
    pub legend: Option<(String, String)>,
}

const BAR: RGBColor = RGBColor(0x2c, 0x7f, 0xb8);
const BAR_HIGHLIGHT: RGBColor = RGBColor(0xc0, 0x39, 0x2b);
const BAR_SECOND: RGBColor = RGBColor(0x27, 0xae, 0x60);
/// Width of the bars' area, px.
const BARS_PX: f64 = 430.0;
/// Height of one row, px.
const ROW_PX: f64 = 22.0;

impl BarChart {
    /// The bar chart as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let mut svg = String::new();
        match self.draw(&mut svg) {
            Ok(()) => svg,
            Err(e) => failed(&self.title, e),
        }
    }

    fn draw(&self, svg: &mut String) -> Result<(), String> {
        let values: Vec<f64> = self
            .bars
            .iter()
            .flat_map(|b| std::iter::once(b.value).chain(b.second))
            .chain(self.guides.iter().copied())
            .filter(|v| v.is_finite())
            .collect();
        let mut x = AxisCoord::fit(&self.axis, &values);
        // Whiskers widen a linear axis; on a log axis their ends below its start are cut there.
        if !matches!(x.scale, Scale::Log10) {
            let with_whiskers: Vec<f64> = values
                .iter()
                .copied()
                .chain(
                    self.bars
                        .iter()
                        .flat_map(|b| b.whisker.into_iter().flatten()),
                )
                .filter(|v| v.is_finite())
                .chain([0.0])
                .collect();
            let spec = AxisSpec {
                scale: x.scale,
                ..self.axis.clone()
            };
            x = AxisCoord::fit(&spec, &with_whiskers);
        }
        let rows = self.bars.len().max(1);
        let y = AxisCoord {
            scale: Scale::Linear,
            from: rows as f64,
            to: 0.0,
            ticks: Vec::new(),
        };

        let label_px = self
            .bars
            .iter()
            .map(|b| text_width_px(&b.label, LABEL_PX))
            .fold(60.0, f64::max);
        let note_px = self
            .bars
            .iter()
            .map(|b| text_width_px(&b.note, LABEL_PX))
            .fold(40.0, f64::max);
        let left = label_px + 16.0;
        let right = note_px + 16.0;
        let width = left + BARS_PX + right;
        let title = wrap(&self.title, width - 20.0, TITLE_PX);
        let axis_lines = wrap(&self.axis.label, BARS_PX + right - 10.0, LABEL_PX);
        let legend_px = if self.legend.is_some() { 22.0 } else { 0.0 };
        let top = 12.0 + 1.3 * TITLE_PX * title.len() as f64 + legend_px + 8.0;
        let bottom_px = 2.0 * LABEL_PX + 1.3 * LABEL_PX * axis_lines.len() as f64 + 8.0;
        let height = top + ROW_PX * rows as f64 + bottom_px;

        let backend = SVGBackend::with_string(svg, (width.ceil() as u32, height.ceil() as u32));
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        centred_lines(&root, &title, 0.5 * width, 8.0, TITLE_PX)?;
        let mut chart = ChartBuilder::on(&root)
            .margin_top(top as i32)
            .margin_left(left as i32)
            .margin_right(right as i32)
            .x_label_area_size((bottom_px) as i32)
            .build_cartesian_2d(x.clone(), y)
            .map_err(|e| e.to_string())?;
        let tick = |v: &f64| format_tick(*v);
        chart
            .configure_mesh()
            .disable_y_mesh()
            .disable_y_axis()
            .bold_line_style(GRID)
            .label_style(font(LABEL_PX))
            .x_label_formatter(&tick)
            .draw()
            .map_err(|e| e.to_string())?;
        let (px_x, px_y) = chart.plotting_area().get_pixel_range();

        // Guides: zero solid (where the axis has one), the others dashed.
        let rows_f = rows as f64;
        if !matches!(x.scale, Scale::Log10) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(0.0, 0.0), (0.0, rows_f)],
                    RGBColor(0x88, 0x88, 0x88),
                )))
                .map_err(|e| e.to_string())?;
        }
        chart
            .draw_series(self.guides.iter().filter(|g| g.is_finite()).map(|g| {
                DashedPathElement::new(
                    vec![(*g, 0.0), (*g, rows_f)],
                    4,
                    3,
                    RGBColor(0x88, 0x88, 0x88),
                )
            }))
            .map_err(|e| e.to_string())?;

        let base = x.base();
        for (i, b) in self.bars.iter().enumerate() {
            let row = i as f64;
            let colour = if b.highlight { BAR_HIGHLIGHT } else { BAR };
            let thick = if b.second.is_some() { 0.36 } else { 0.64 };
            if b.value.is_finite() {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(base, row + 0.14), (b.value, row + 0.14 + thick)],
                        colour.filled(),
                    )))
                    .map_err(|e| e.to_string())?;
            }
            if let Some(v) = b.second.filter(|v| v.is_finite()) {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(base, row + 0.52), (v, row + 0.88)],
                        BAR_SECOND.filled(),
                    )))
                    .map_err(|e| e.to_string())?;
            }
            if let Some([w0, w1]) = b.whisker.filter(|w| w.iter().all(|v| v.is_finite())) {
                let mid = row + 0.46;
                chart
                    .draw_series([
                        PathElement::new(vec![(w0, mid), (w1, mid)], BLACK),
                        PathElement::new(vec![(w0, mid - 0.18), (w0, mid + 0.18)], BLACK),
                        PathElement::new(vec![(w1, mid - 0.18), (w1, mid + 0.18)], BLACK),
                    ])
                    .map_err(|e| e.to_string())?;
            }
            let (_, cy) = chart.backend_coord(&(base, row + 0.5));
            root.draw(&Text::new(
                b.label.clone(),
                (px_x.start - 8, cy),
                font(LABEL_PX).pos(Pos::new(HPos::Right, VPos::Center)),
            ))
            .map_err(|e| e.to_string())?;
            root.draw(&Text::new(
                b.note.clone(),
                (px_x.end + 8, cy),
                font(LABEL_PX).pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(|e| e.to_string())?;
        }

        // The axis label under the tick labels, left-aligned with the bars.
        let label_top = f64::from(px_y.end) + 2.0 * LABEL_PX + 2.0;
        for (i, line) in axis_lines.iter().enumerate() {
            let y = label_top + 1.3 * LABEL_PX * i as f64;
            root.draw(&Text::new(
                line.clone(),
                (px_x.start, y as i32),
                font(LABEL_PX).pos(Pos::new(HPos::Left, VPos::Top)),
            ))
            .map_err(|e| e.to_string())?;
        }
        if let Some((first, second)) = &self.legend {
            let y = (12.0 + 1.3 * TITLE_PX * title.len() as f64) as i32;
            let mut x0 = px_x.start;
            for (name, colour) in [(first, BAR), (second, BAR_SECOND)] {
                root.draw(&Rectangle::new(
                    [(x0, y + 2), (x0 + 10, y + 10)],
                    colour.filled(),
                ))
                .map_err(|e| e.to_string())?;
                root.draw(&Text::new(
                    name.clone(),
                    (x0 + 14, y + 6),
                    font(LABEL_PX).pos(Pos::new(HPos::Left, VPos::Center)),
                ))
                .map_err(|e| e.to_string())?;
                x0 += (text_width_px(name, LABEL_PX) + 40.0) as i32;
            }
        }
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }
}
