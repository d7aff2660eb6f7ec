//! A small dependency-free SVG plot writer for reports: line plots (spectra, wear versus time),
//! step histograms (contact-pressure PDFs, thesis Figure 6.65, with marker lines such as the
//! yield strength and the wear-law cutoff) and scatter plots (contact locations, Figures
//! 6.59-6.62).
//!
//! Points that cannot be drawn (non-finite, or <= 0 on a log axis) are skipped, as plotting
//! tools usually do; a line is broken at them.

use std::fmt::Write;

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic; only positive values are drawn.
    Log10,
}

/// One axis: label (with its unit, e.g. "frequency (Hz)"), scale and optional fixed range.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisSpec {
    /// Label including the unit.
    pub label: String,
    /// Scale.
    pub scale: Scale,
    /// Fixed `(min, max)`; `None` fits the data (rounded out to ticks or whole decades).
    pub range: Option<(f64, f64)>,
}

impl AxisSpec {
    /// Linear axis fitted to the data.
    pub fn linear(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            scale: Scale::Linear,
            range: None,
        }
    }

    /// Log axis fitted to the data.
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            scale: Scale::Log10,
            range: None,
        }
    }

    /// Same axis with a fixed range.
    pub fn with_range(mut self, min: f64, max: f64) -> Self {
        self.range = Some((min, max));
        self
    }
}

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

/// A plot: title, axes, series and markers; `to_svg` renders it.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    /// Title drawn above the plot area.
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
    pub width_px: f64,
    /// Image height, px.
    pub height_px: f64,
}

/// Plot-area margins, px: left (tick labels and y label), right, top (title), bottom.
const MARGIN_LEFT: f64 = 78.0;
const MARGIN_RIGHT: f64 = 20.0;
const MARGIN_TOP: f64 = 36.0;
const MARGIN_BOTTOM: f64 = 52.0;
const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// Maps data values on one axis to pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisMap {
    /// Scale.
    pub scale: Scale,
    /// Data value at the start of the axis.
    pub min: f64,
    /// Data value at the end of the axis.
    pub max: f64,
    /// Pixel coordinate of `min`.
    pub px_min: f64,
    /// Pixel coordinate of `max`.
    pub px_max: f64,
}

impl AxisMap {
    /// Pixel coordinate of `value`, or `None` if it cannot be drawn on this scale.
    pub fn map(&self, value: f64) -> Option<f64> {
        let (v, lo, hi) = match self.scale {
            Scale::Linear => (value, self.min, self.max),
            Scale::Log10 => {
                if value <= 0.0 {
                    return None;
                }
                (value.log10(), self.min.log10(), self.max.log10())
            }
        };
        if !v.is_finite() {
            return None;
        }
        Some(self.px_min + (v - lo) / (hi - lo) * (self.px_max - self.px_min))
    }

    /// Tick values inside the range: 1-2-5 steps (linear) or whole decades (log).
    pub fn ticks(&self) -> Vec<f64> {
        match self.scale {
            Scale::Linear => {
                let step = nice_step((self.max - self.min) / 5.0);
                let first = (self.min / step).ceil() as i64;
                let last = (self.max / step + 1e-9).floor() as i64;
                (first..=last).map(|k| k as f64 * step).collect()
            }
            Scale::Log10 => {
                let first = (self.min.log10() - 1e-9).ceil() as i32;
                let last = (self.max.log10() + 1e-9).floor() as i32;
                (first..=last).map(|k| 10f64.powi(k)).collect()
            }
        }
    }
}

/// Pixel frame of a plot: where the plot area sits and how each axis maps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotFrame {
    /// Horizontal mapping (left to right).
    pub x: AxisMap,
    /// Vertical mapping (`px_min` at the bottom, larger data values upwards).
    pub y: AxisMap,
}

fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let magnitude = 10f64.powf(raw.log10().floor());
    let fraction = raw / magnitude;
    let nice = if fraction <= 1.0 {
        1.0
    } else if fraction <= 2.0 {
        2.0
    } else if fraction <= 5.0 {
        5.0
    } else {
        10.0
    };
    nice * magnitude
}

/// Data range of `values` drawable on `axis`, rounded outwards (ticks or decades).
fn fit_range(axis: &AxisSpec, values: impl Iterator<Item = f64>) -> (f64, f64) {
    if let Some((lo, hi)) = axis.range {
        let valid = lo.is_finite()
            && hi.is_finite()
            && hi > lo
            && (axis.scale == Scale::Linear || lo > 0.0);
        if valid {
            return (lo, hi);
        }
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if v.is_finite() && (axis.scale == Scale::Linear || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    match axis.scale {
        Scale::Linear => {
            if lo > hi {
                return (0.0, 1.0);
            }
            if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
                lo -= 1.0;
                hi += 1.0;
            }
            let step = nice_step((hi - lo) / 5.0);
            ((lo / step).floor() * step, (hi / step).ceil() * step)
        }
        Scale::Log10 => {
            if lo > hi {
                return (1.0, 10.0);
            }
            let (a, mut b) = (lo.log10().floor(), hi.log10().ceil());
            if b <= a {
                b = a + 1.0;
            }
            (10f64.powf(a), 10f64.powf(b))
        }
    }
}

/// Compact tick label: plain decimals between 1e-3 and 1e5, otherwise `1.5e-6` style.
fn format_tick(value: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    let magnitude = value.abs();
    if !(1e-3..1e5).contains(&magnitude) {
        let text = format!("{value:e}");
        return text;
    }
    let text = format!("{value:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// Escapes text for SVG element content and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(ch),
        }
    }
    out
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
            width_px: 720.0,
            height_px: 440.0,
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

    /// The pixel frame this plot is drawn in (ranges fitted to the data as `to_svg` does).
    pub fn frame(&self) -> PlotFrame {
        let width = self.width_px.max(MARGIN_LEFT + MARGIN_RIGHT + 10.0);
        let height = self.height_px.max(MARGIN_TOP + MARGIN_BOTTOM + 10.0);
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .chain(self.markers.iter().map(|m| m.x));
        let ys = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1));
        let (x_min, x_max) = fit_range(&self.x_axis, xs);
        let (y_min, y_max) = fit_range(&self.y_axis, ys);
        PlotFrame {
            x: AxisMap {
                scale: self.x_axis.scale,
                min: x_min,
                max: x_max,
                px_min: MARGIN_LEFT,
                px_max: width - MARGIN_RIGHT,
            },
            y: AxisMap {
                scale: self.y_axis.scale,
                min: y_min,
                max: y_max,
                px_min: height - MARGIN_BOTTOM,
                px_max: MARGIN_TOP,
            },
        }
    }

    /// Renders the plot as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let frame = self.frame();
        let (left, right) = (frame.x.px_min, frame.x.px_max);
        let (bottom, top) = (frame.y.px_min, frame.y.px_max);
        let width = right + MARGIN_RIGHT;
        let height = bottom + MARGIN_BOTTOM;
        let mut svg = String::new();
        // Writing to a String cannot fail; results are ignored with `let _`.
        let _ = write!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" font-size="12">"#
        );
        let _ = write!(
            svg,
            r#"<defs><clipPath id="plot-area"><rect x="{left:.2}" y="{top:.2}" width="{:.2}" height="{:.2}"/></clipPath></defs>"#,
            right - left,
            bottom - top
        );
        let _ = write!(
            svg,
            r#"<rect x="0" y="0" width="{width:.0}" height="{height:.0}" fill="white"/>"#
        );
        let _ = write!(
            svg,
            r#"<text x="{:.2}" y="22" text-anchor="middle" font-size="14">{}</text>"#,
            0.5 * (left + right),
            escape(&self.title)
        );
        self.write_axes(&mut svg, &frame);
        for (i, series) in self.series.iter().enumerate() {
            write_series(&mut svg, &frame, series, PALETTE[i % PALETTE.len()]);
        }
        for marker in &self.markers {
            if let Some(px) = frame.x.map(marker.x) {
                let _ = write!(
                    svg,
                    r##"<line x1="{px:.2}" y1="{top:.2}" x2="{px:.2}" y2="{bottom:.2}" stroke="#444" stroke-dasharray="6 4"/><text x="{:.2}" y="{:.2}" font-size="11">{}</text>"##,
                    px + 3.0,
                    top + 12.0,
                    escape(&marker.label)
                );
            }
        }
        self.write_legend(&mut svg, &frame);
        svg.push_str("</svg>\n");
        svg
    }

    fn write_axes(&self, svg: &mut String, frame: &PlotFrame) {
        let (left, right) = (frame.x.px_min, frame.x.px_max);
        let (bottom, top) = (frame.y.px_min, frame.y.px_max);
        let _ = write!(
            svg,
            r##"<rect x="{left:.2}" y="{top:.2}" width="{:.2}" height="{:.2}" fill="none" stroke="#000"/>"##,
            right - left,
            bottom - top
        );
        for tick in frame.x.ticks() {
            if let Some(px) = frame.x.map(tick) {
                let _ = write!(
                    svg,
                    r##"<line x1="{px:.2}" y1="{bottom:.2}" x2="{px:.2}" y2="{:.2}" stroke="#000"/><line x1="{px:.2}" y1="{top:.2}" x2="{px:.2}" y2="{bottom:.2}" stroke="#ddd"/><text x="{px:.2}" y="{:.2}" text-anchor="middle">{}</text>"##,
                    bottom + 5.0,
                    bottom + 18.0,
                    escape(&format_tick(tick))
                );
            }
        }
        for tick in frame.y.ticks() {
            if let Some(py) = frame.y.map(tick) {
                let _ = write!(
                    svg,
                    r##"<line x1="{:.2}" y1="{py:.2}" x2="{left:.2}" y2="{py:.2}" stroke="#000"/><line x1="{left:.2}" y1="{py:.2}" x2="{right:.2}" y2="{py:.2}" stroke="#ddd"/><text x="{:.2}" y="{:.2}" text-anchor="end">{}</text>"##,
                    left - 5.0,
                    left - 8.0,
                    py + 4.0,
                    escape(&format_tick(tick))
                );
            }
        }
        let _ = write!(
            svg,
            r#"<text x="{:.2}" y="{:.2}" text-anchor="middle">{}</text>"#,
            0.5 * (left + right),
            bottom + 40.0,
            escape(&self.x_axis.label)
        );
        let (lx, ly) = (16.0, 0.5 * (top + bottom));
        let _ = write!(
            svg,
            r#"<text x="{lx:.2}" y="{ly:.2}" text-anchor="middle" transform="rotate(-90 {lx:.2} {ly:.2})">{}</text>"#,
            escape(&self.y_axis.label)
        );
    }

    fn write_legend(&self, svg: &mut String, frame: &PlotFrame) {
        if self.series.is_empty() {
            return;
        }
        let x = frame.x.px_max - 170.0;
        let mut y = frame.y.px_max + 16.0;
        for (i, series) in self.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let _ = match series.kind {
                SeriesKind::Line => write!(
                    svg,
                    r#"<line x1="{x:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}" stroke="{color}" stroke-width="2"/>"#,
                    x + 20.0
                ),
                SeriesKind::Markers => write!(
                    svg,
                    r#"<circle cx="{:.2}" cy="{y:.2}" r="3" fill="{color}"/>"#,
                    x + 10.0
                ),
            };
            let _ = write!(
                svg,
                r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
                x + 26.0,
                y + 4.0,
                escape(&series.name)
            );
            y += 16.0;
        }
    }
}

fn write_series(svg: &mut String, frame: &PlotFrame, series: &Series, color: &str) {
    let mapped = series
        .points
        .iter()
        .map(|&(x, y)| frame.x.map(x).zip(frame.y.map(y)));
    match series.kind {
        SeriesKind::Line => {
            let mut run: Vec<(f64, f64)> = Vec::new();
            let flush = |run: &mut Vec<(f64, f64)>, svg: &mut String| {
                if run.len() >= 2 {
                    let _ = write!(
                        svg,
                        r#"<polyline fill="none" stroke="{color}" stroke-width="1.5" clip-path="url(#plot-area)" points=""#
                    );
                    for (i, (px, py)) in run.iter().enumerate() {
                        let sep = if i == 0 { "" } else { " " };
                        let _ = write!(svg, "{sep}{px:.2},{py:.2}");
                    }
                    svg.push_str(r#""/>"#);
                }
                run.clear();
            };
            for point in mapped {
                match point {
                    Some(p) => run.push(p),
                    None => flush(&mut run, svg),
                }
            }
            flush(&mut run, svg);
        }
        SeriesKind::Markers => {
            let _ = write!(svg, r#"<g fill="{color}" clip-path="url(#plot-area)">"#);
            for (px, py) in mapped.flatten() {
                let _ = write!(svg, r#"<circle cx="{px:.2}" cy="{py:.2}" r="2.5"/>"#);
            }
            svg.push_str("</g>");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks that every element opened is closed in order; returns the element count.
    fn balanced(svg: &str) -> usize {
        let mut stack: Vec<String> = Vec::new();
        let mut count = 0;
        let mut rest = svg;
        while let Some(start) = rest.find('<') {
            let end = rest[start..].find('>').expect("unterminated tag") + start;
            let tag = &rest[start + 1..end];
            assert!(!tag.contains('<'), "nested '<' in tag {tag}");
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(name.trim()),
                    "mismatched </{name}>"
                );
            } else if !tag.ends_with('/') {
                let name = tag.split_whitespace().next().unwrap_or_default();
                stack.push(name.to_string());
                count += 1;
            } else {
                count += 1;
            }
            // text between tags must not contain a raw '>' or unescaped '&'
            let next = rest[end + 1..]
                .find('<')
                .map_or(rest.len(), |i| i + end + 1);
            let text = &rest[end + 1..next];
            assert!(!text.contains('>'), "raw '>' in text {text}");
            rest = &rest[next..];
        }
        assert!(stack.is_empty(), "unclosed {stack:?}");
        count
    }

    #[test]
    fn output_is_balanced_and_escaped() {
        let plot = Plot::new(
            "Pressure <PDF> & \"cutoff\"",
            AxisSpec::linear("contact pressure (MPa)"),
            AxisSpec::log("probability density (1/MPa)"),
        )
        .with_series(Series::histogram(
            "mid shoe & rail",
            &[0.0, 100.0, 200.0, 300.0],
            &[1e-3, 4e-3, 0.0],
        ))
        .with_series(Series::line(
            "fit",
            vec![(0.0, 1e-3), (f64::NAN, 1.0), (50.0, 2e-3), (300.0, 5e-4)],
        ))
        .with_series(Series::scatter("points", vec![(10.0, 1e-3), (20.0, -1.0)]))
        .with_marker(435.0, "Sy")
        .with_marker(870.0, "cutoff 2 Sy");
        let svg = plot.to_svg();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(balanced(&svg) > 20);
        assert!(svg.contains("Pressure &lt;PDF&gt; &amp; &quot;cutoff&quot;"));
        assert!(svg.contains("mid shoe &amp; rail"));
        assert!(svg.contains(">Sy</text>") && svg.contains(">cutoff 2 Sy</text>"));
        // markers widen the x range to include them
        assert!(plot.frame().x.max >= 870.0);
        // empty plot still renders
        assert!(
            balanced(&Plot::new("", AxisSpec::linear("x"), AxisSpec::linear("y")).to_svg()) > 3
        );
    }

    #[test]
    fn points_map_to_expected_pixels() {
        let plot = Plot::new(
            "scatter",
            AxisSpec::linear("z (mm)").with_range(0.0, 100.0),
            AxisSpec::log("y (N)").with_range(1.0, 1000.0),
        )
        .with_series(Series::scatter("contacts", vec![(25.0, 10.0)]));
        let frame = plot.frame();
        // Plot area: x from 78 to 700 px (720 wide, 20 right margin), y from 388 (bottom,
        // 440 - 52) up to 36. x = 25 is a quarter across; y = 10 is one of three decades up.
        let px = 78.0 + 0.25 * (700.0 - 78.0);
        let py = 388.0 - (388.0 - 36.0) / 3.0;
        assert!((frame.x.map(25.0).unwrap() - px).abs() < 1e-9);
        assert!((frame.y.map(10.0).unwrap() - py).abs() < 1e-9);
        assert!(frame.y.map(0.0).is_none());
        let svg = plot.to_svg();
        assert!(
            svg.contains(&format!(r#"<circle cx="{px:.2}" cy="{py:.2}" r="2.5"/>"#)),
            "{svg}"
        );
        // Ticks: linear 0, 20, ..., 100; log decades 1, 10, 100, 1000.
        assert_eq!(frame.x.ticks(), vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
        assert_eq!(frame.y.ticks(), vec![1.0, 10.0, 100.0, 1000.0]);
        assert!(svg.contains(">1000</text>") && svg.contains(">80</text>"));
    }

    #[test]
    fn tick_labels_are_compact() {
        assert_eq!(format_tick(0.30000000000000004), "0.3");
        assert_eq!(format_tick(2.5e-6), "2.5e-6");
        assert_eq!(format_tick(1e6), "1e6");
        assert_eq!(format_tick(-40.0), "-40");
    }
}
