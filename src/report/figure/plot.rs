//! Line, step-histogram and scatter plots with vertical markers and a legend.

use super::axis::AxisCoord;
use super::{centred_lines, failed, font, format_tick, text_width_px, wrap, AxisSpec};
use super::{GRID, GUIDE, LABEL_PX, PALETTE, TITLE_PX};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesKind {
    /// Polyline through the points.
    Line,
    /// Circles at the points.
    Markers,
}

/// A named data series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// `(x, y)` points in axis units.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub kind: SeriesKind,
}

impl Series {
    /// A line through `points`.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            kind: SeriesKind::Line,
        }
    }

    /// Scatter markers at `points`.
    pub fn scatter(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            kind: SeriesKind::Markers,
        }
    }

    /// Step outline of a histogram with `bin_edges.len() == values.len() + 1`, dropping to zero
    /// at both outer edges (extra values or edges beyond the shorter list are ignored).
    pub fn histogram(name: impl Into<String>, bin_edges: &[f64], values: &[f64]) -> Self {
        let bins = values.len().min(bin_edges.len().saturating_sub(1));
        let mut points = Vec::with_capacity(2 * bins + 2);
        if bins > 0 {
            points.push((bin_edges[0], 0.0));
            for i in 0..bins {
                points.push((bin_edges[i], values[i]));
                points.push((bin_edges[i + 1], values[i]));
            }
            points.push((bin_edges[bins], 0.0));
        }
        Self::line(name, points)
    }
}

/// A labelled vertical line at `x` (e.g. "Sy" or "cutoff" on a pressure PDF).
#[derive(Debug, Clone, PartialEq)]
pub struct VerticalMarker {
    /// Position in x-axis units.
    pub x: f64,
    /// Label drawn at the top of the line.
    pub label: String,
}

/// A plot: title, axes, series and markers; [`Plot::to_svg`] renders it.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// Title drawn above the plot area (broken into lines if wider than the image).
    pub title: String,
    /// Horizontal axis.
    pub x_axis: AxisSpec,
    /// Vertical axis.
    pub y_axis: AxisSpec,
    /// Data series, drawn in order.
    pub series: Vec<Series>,
    /// Vertical marker lines.
    pub markers: Vec<VerticalMarker>,
    /// Image width, px.
    pub width_px: u32,
    /// Image height, px.
    pub height_px: u32,
}

impl Plot {
    /// An empty 720 x 440 px plot.
    pub fn new(title: impl Into<String>, x_axis: AxisSpec, y_axis: AxisSpec) -> Self {
        Self {
            title: title.into(),
            x_axis,
            y_axis,
            series: Vec::new(),
            markers: Vec::new(),
            width_px: 720,
            height_px: 440,
        }
    }

    /// Adds a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a vertical marker line.
    pub fn with_marker(mut self, x: f64, label: impl Into<String>) -> Self {
        self.markers.push(VerticalMarker {
            x,
            label: label.into(),
        });
        self
    }

    /// Renders the plot as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let mut svg = String::new();
        match self.draw(&mut svg) {
            Ok(()) => svg,
            Err(e) => failed(&self.title, e),
        }
    }

    fn draw(&self, svg: &mut String) -> Result<(), String> {
        let xs: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .chain(self.markers.iter().map(|m| m.x))
            .collect();
        let ys: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .collect();
        let x = AxisCoord::fit(&self.x_axis, &xs);
        let y = AxisCoord::fit(&self.y_axis, &ys);

        // Room for the y tick labels, and the image wide enough for the title.
        let y_tick_px = y
            .ticks
            .iter()
            .map(|t| text_width_px(&format_tick(*t), LABEL_PX))
            .fold(0.0, f64::max);
        let width = f64::from(self.width_px.max(320));
        let title = wrap(&self.title, width - 20.0, TITLE_PX);
        let title_px = 1.3 * TITLE_PX * title.len() as f64 + 12.0;
        let legend_px = self
            .series
            .iter()
            .map(|s| text_width_px(&s.name, LABEL_PX))
            .fold(0.0, f64::max);
        let height = f64::from(self.height_px.max(200));
        // The last x tick label is centred on the plot's right edge: half of it must fit.
        let last_x_tick = x
            .ticks
            .last()
            .map_or(0.0, |t| text_width_px(&format_tick(*t), LABEL_PX));
        let right = (0.5 * last_x_tick + 4.0).max(20.0);

        let backend = SVGBackend::with_string(svg, (width as u32, height as u32));
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        centred_lines(&root, &title, 0.5 * width, 8.0, TITLE_PX)?;
        let mut chart = ChartBuilder::on(&root)
            .margin_top(title_px as i32)
            .margin_right(right as i32)
            .margin_left(6)
            .margin_bottom(6)
            .x_label_area_size((2.0 * LABEL_PX + 24.0) as i32)
            .y_label_area_size((y_tick_px + 14.0 + 1.5 * LABEL_PX) as i32)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(|e| e.to_string())?;
        let tick = |v: &f64| format_tick(*v);
        chart
            .configure_mesh()
            .bold_line_style(GRID)
            .x_desc(self.x_axis.label.as_str())
            .y_desc(self.y_axis.label.as_str())
            .label_style(font(LABEL_PX))
            .axis_desc_style(font(LABEL_PX))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .draw()
            .map_err(|e| e.to_string())?;

        for (i, series) in self.series.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            let drawable = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
            match series.kind {
                SeriesKind::Line => {
                    // A line is broken at points that cannot be drawn.
                    for run in series.points.split(|p| !drawable(&p)) {
                        if run.len() >= 2 {
                            chart
                                .draw_series(LineSeries::new(
                                    run.iter().copied(),
                                    colour.stroke_width(2),
                                ))
                                .map_err(|e| e.to_string())?;
                        }
                    }
                }
                SeriesKind::Markers => {
                    chart
                        .draw_series(
                            series
                                .points
                                .iter()
                                .filter(drawable)
                                .map(|p| Circle::new(*p, 3, colour.filled())),
                        )
                        .map_err(|e| e.to_string())?;
                }
            }
        }

        let (px_x, px_y) = chart.plotting_area().get_pixel_range();
        // Marker labels one under the other, so two markers close together do not overprint.
        let marker_row = (1.4 * LABEL_PX) as i32;
        for (i, marker) in self.markers.iter().filter(|m| m.x.is_finite()).enumerate() {
            let top = y.from.max(y.to);
            let bottom = y.from.min(y.to);
            chart
                .draw_series(std::iter::once(DashedPathElement::new(
                    vec![(marker.x, bottom), (marker.x, top)],
                    6,
                    4,
                    GUIDE.stroke_width(1),
                )))
                .map_err(|e| e.to_string())?;
            let (mx, _) = chart.backend_coord(&(marker.x, top));
            // The label beside its line, on the side with room for it.
            let label_px = text_width_px(&marker.label, LABEL_PX);
            let (anchor, lx) = if f64::from(mx) + 4.0 + label_px <= f64::from(px_x.end) {
                (HPos::Left, mx + 4)
            } else {
                (HPos::Right, mx - 4)
            };
            root.draw(&Text::new(
                marker.label.clone(),
                (lx, px_y.start + 4 + marker_row * i as i32),
                font(LABEL_PX).pos(Pos::new(anchor, VPos::Top)),
            ))
            .map_err(|e| e.to_string())?;
        }

        // The legend: upper right inside the plot area, on a white box.
        if !self.series.is_empty() {
            let row = (1.4 * LABEL_PX) as i32;
            let box_w = (legend_px + 40.0) as i32;
            let x0 = px_x.end - box_w - 8;
            let y0 = px_y.start + 8 + marker_row * self.markers.len() as i32;
            let box_h = row * self.series.len() as i32 + 8;
            root.draw(&Rectangle::new(
                [(x0, y0), (x0 + box_w, y0 + box_h)],
                WHITE.mix(0.85).filled(),
            ))
            .map_err(|e| e.to_string())?;
            root.draw(&Rectangle::new([(x0, y0), (x0 + box_w, y0 + box_h)], GRID))
                .map_err(|e| e.to_string())?;
            for (i, series) in self.series.iter().enumerate() {
                let colour = PALETTE[i % PALETTE.len()];
                let cy = y0 + 4 + row * i as i32 + row / 2;
                match series.kind {
                    SeriesKind::Line => root.draw(&PathElement::new(
                        vec![(x0 + 6, cy), (x0 + 26, cy)],
                        colour.stroke_width(2),
                    )),
                    SeriesKind::Markers => {
                        root.draw(&Circle::new((x0 + 16, cy), 3, colour.filled()))
                    }
                }
                .map_err(|e| e.to_string())?;
                root.draw(&Text::new(
                    series.name.clone(),
                    (x0 + 32, cy),
                    font(LABEL_PX).pos(Pos::new(HPos::Left, VPos::Center)),
                ))
                .map_err(|e| e.to_string())?;
            }
        }
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }
}
