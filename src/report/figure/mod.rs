//! The report's and the diagnosis' figures, drawn by `plotters` on its SVG backend: line plots
//! (wear versus time, spectra, the penalization curve and its bands), step histograms
//! (contact-pressure PDFs, thesis Figure 6.65, with the yield strength and the wear-law cutoff
//! marked), scatter plots and horizontal bar charts ([`BarChart`]: the diagnosis' residuals,
//! ranking, before/after and energy budget).
//!
//! plotters draws; this module holds the layout policy plotters leaves to its user:
//! - the scale of an axis: [`AxisSpec::auto`] takes a log axis where the data's magnitudes span
//!   more than two decades (a symmetric log, linear within a decade of zero, when the data also
//!   go below zero, as a ranking's gains do), otherwise a linear one;
//! - ticks at round values (1-2-5 steps, whole decades) with compact labels ([`format_tick`]);
//! - room for every text: an SVG carries no font metrics, so widths are estimated at
//!   [`EM_PER_CHAR`] of the font size a character, an upper bound for sans-serif text, and the
//!   margins, the image width and the line breaks of long titles follow from it.
//!
//! Points that cannot be drawn (not finite) are skipped and a line is broken at them; on a log
//! axis a value at or below the axis' start (zero, a histogram's empty bin) is drawn at it.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

mod axis;
mod bars;
mod plot;
#[cfg(test)]
mod tests;

pub use axis::{format_tick, spans_decades, AxisSpec, Scale};
pub use bars::{Bar, BarChart};
pub use plot::{Plot, Series, SeriesKind, VerticalMarker};

/// Width of one character as a share of the font size, for layout. Sans-serif fonts average
/// about 0.5 em; digits and capitals run wider, so 0.6 keeps every estimate on the safe side.
pub const EM_PER_CHAR: f64 = 0.6;

/// Font sizes in SVG pixels: labels and ticks, titles.
const LABEL_PX: f64 = 12.0;
const TITLE_PX: f64 = 14.0;
/// plotters writes a font's size divided by 1.24 into the SVG; these give the sizes above.
const PLOTTERS_FONT_SCALE: f64 = 1.24;

const PALETTE: [RGBColor; 8] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x17, 0xbe, 0xcf),
];
const GRID: RGBColor = RGBColor(0xdd, 0xdd, 0xdd);
const GUIDE: RGBColor = RGBColor(0x44, 0x44, 0x44);

/// Estimated width of `text` at `font_px`, px.
pub fn text_width_px(text: &str, font_px: f64) -> f64 {
    EM_PER_CHAR * font_px * text.chars().count() as f64
}

fn font(px: f64) -> TextStyle<'static> {
    ("sans-serif", px * PLOTTERS_FONT_SCALE).into_font().into()
}

/// `text` broken at spaces into lines no wider than `max_px` (a single word may be wider).
fn wrap(text: &str, max_px: f64, font_px: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if !line.is_empty() && text_width_px(&candidate, font_px) > max_px {
            lines.push(std::mem::replace(&mut line, word.to_string()));
        } else {
            line = candidate;
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// Drawing failed (plotters reports it; writing into a String does not fail in practice).
fn failed(what: &str, error: impl std::fmt::Display) -> String {
    tracing::warn!(%error, "drawing {what}");
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="360" height="40" viewBox="0 0 360 40"><text x="8" y="24" font-family="sans-serif" font-size="12">{} could not be drawn</text></svg>"#,
        what.replace(['<', '>', '&', '"'], " ")
    )
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Draws `lines` of text at `font_px`, centred on `x`, the first line's top at `top`.
fn centred_lines(
    area: &Area,
    lines: &[String],
    x: f64,
    top: f64,
    font_px: f64,
) -> Result<(), String> {
    let style = font(font_px).pos(Pos::new(HPos::Center, VPos::Top));
    for (i, line) in lines.iter().enumerate() {
        let y = top + 1.3 * font_px * i as f64;
        area.draw(&Text::new(
            line.clone(),
            (x as i32, y as i32),
            style.clone(),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}
