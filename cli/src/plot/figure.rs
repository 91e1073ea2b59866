//! The plots of `eomgen simulate`, drawn with `plotters`: a line per series against time, with
//! axes, ticks and tick labels, a light grid, axis titles with units, a title and a legend.
//!
//! The format comes from the file's extension: SVG (text as `<text>` elements) or PNG (text
//! rasterized with DejaVu Sans, embedded in the binary: no system font is needed). The same
//! figure gives the same bytes. Files are written through a temporary file and a rename.

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// The picture's size in pixels.
pub const WIDTH: u32 = 960;
pub const HEIGHT: u32 = 540;
/// The legend's column, right of the chart.
const LEGEND: u32 = 210;
const FONT: &str = "sans-serif";

/// How a plot is encoded, from its file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    /// The format of `path`, or the one-line error naming it and the accepted extensions.
    pub fn of(path: &Path) -> Result<Format, String> {
        let ext = path.extension().and_then(|e| e.to_str());
        match ext.map(str::to_ascii_lowercase).as_deref() {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(format!(
                "--plot {}: unknown plot format; the file name must end in .svg or .png",
                path.display()
            )),
        }
    }
}

/// The file beside `path` for another plot: `run/ur5.svg` and `velocities` give
/// `run/ur5-velocities.svg`.
pub fn sibling(path: &Path, what: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let ext = path.extension().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}-{what}.{ext}"))
}

/// The unit of a quantity over joints that rotate (`rotating`) or slide: `rad`, `m`, or both
/// when mixed (`rad or m`).
pub fn unit(rotating: &[bool], angular: &str, linear: &str) -> String {
    match (rotating.iter().any(|&r| r), rotating.iter().any(|&r| !r)) {
        (true, true) => format!("{angular} or {linear}"),
        (false, true) => linear.to_string(),
        _ => angular.to_string(),
    }
}

/// One figure: named series sampled at `times` (`values[k][j]` is series `j` at `times[k]`).
pub struct Figure<'a> {
    pub title: String,
    /// The vertical axis's title, with its unit.
    pub y_label: String,
    pub names: Vec<String>,
    pub times: &'a [f64],
    pub values: &'a [Vec<f64>],
}

/// Ten distinct colours (the common "category10" palette).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// At most this many points per line (every sample when fewer).
const MAX_POINTS: usize = 2000;

fn fonts() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // DejaVu Sans is a valid TrueType font: registering it cannot fail.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// The finite range of the values, widened a little (and made non-empty).
fn range(values: &[Vec<f64>]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.iter().flatten().filter(|x| x.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if lo > hi {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(hi.abs()) || span == 0.0 {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - pad, hi + pad);
    }
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// A tick label for `v` on an axis spanning `span` whose values reach `magnitude`: a fixed
/// number of decimals for the axis (as many as a fifth of the span needs, more for a tick that
/// needs them), scientific notation for very small or very large numbers, and "0" for zero
/// (or rounding noise around it).
fn tick(v: f64, span: f64, magnitude: f64) -> String {
    if v.abs() <= 1e-9 * span {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&magnitude) || span < 1e-4 * magnitude {
        return format!("{v:.2e}");
    }
    let mut decimals = (-(span / 5.0).log10()).ceil().clamp(0.0, 6.0) as i32;
    while decimals < 6
        && ((v * 10f64.powi(decimals)).round() / 10f64.powi(decimals) - v).abs() > 1e-6 * span
    {
        decimals += 1;
    }
    format!("{v:.*}", decimals as usize)
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, fig: &Figure) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("cannot draw the plot: {e}");
    root.fill(&WHITE).map_err(e)?;
    let (chart_area, legend) = root.split_horizontally(WIDTH - LEGEND);
    let t0 = fig.times.first().copied().unwrap_or(0.0);
    let t1 = fig.times.last().copied().unwrap_or(1.0).max(t0);
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let (lo, hi) = range(fig.values);
    let (y_span, y_mag) = (hi - lo, lo.abs().max(hi.abs()));
    let (x_span, x_mag) = (t1 - t0, t0.abs().max(t1.abs()));
    let x_fmt = move |v: &f64| tick(*v, x_span, x_mag);
    let y_fmt = move |v: &f64| tick(*v, y_span, y_mag);
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(&fig.title, (FONT, 20))
        .margin(14)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(fig.y_label.as_str())
        .x_labels(10)
        .y_labels(8)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .bold_line_style(RGBColor(215, 215, 215))
        .light_line_style(RGBColor(240, 240, 240))
        .x_max_light_lines(2)
        .y_max_light_lines(2)
        .axis_style(BLACK)
        .draw()
        .map_err(e)?;
    let stride = fig.times.len().div_ceil(MAX_POINTS).max(1);
    for (j, _) in fig.names.iter().enumerate() {
        let color = PALETTE[j % PALETTE.len()];
        let last = fig.times.len().saturating_sub(1);
        let points = fig
            .times
            .iter()
            .zip(fig.values)
            .enumerate()
            .filter(|(k, _)| k % stride == 0 || *k == last)
            .filter_map(|(_, (t, v))| v.get(j).filter(|x| x.is_finite()).map(|x| (*t, *x)));
        chart
            .draw_series(LineSeries::new(points, color.stroke_width(2)))
            .map_err(e)?;
    }
    // The legend, in its own column so that it never hides a line.
    let top = 60;
    legend
        .draw(&Text::new("legend", (8, top - 24), (FONT, 14).into_font()))
        .map_err(e)?;
    for (j, name) in fig.names.iter().enumerate() {
        let color = PALETTE[j % PALETTE.len()];
        let y = top + 22 * j as i32;
        legend
            .draw(&PathElement::new(
                vec![(8, y + 8), (34, y + 8)],
                color.stroke_width(3),
            ))
            .map_err(e)?;
        legend
            .draw(&Text::new(name.as_str(), (42, y), (FONT, 14).into_font()))
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

/// The figure encoded as `format`.
pub fn render(fig: &Figure, format: Format) -> Result<Vec<u8>, String> {
    fonts();
    match format {
        Format::Svg => {
            let mut svg = String::new();
            draw(
                SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area(),
                fig,
            )?;
            Ok(svg.into_bytes())
        }
        Format::Png => {
            let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
            draw(
                BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area(),
                fig,
            )?;
            let mut out = Vec::new();
            let mut encoder = png::Encoder::new(&mut out, WIDTH, HEIGHT);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let png = |e: png::EncodingError| format!("cannot encode the PNG: {e}");
            let mut writer = encoder.write_header().map_err(png)?;
            writer.write_image_data(&rgb).map_err(png)?;
            writer.finish().map_err(png)?;
            Ok(out)
        }
    }
}

/// Renders the figure to `path` (format from its extension), atomically.
pub fn write(path: &Path, fig: &Figure) -> Result<(), String> {
    let bytes = render(fig, Format::of(path)?)?;
    eomgen::write_if_changed(path, &bytes)
        .map(|_| ())
        .map_err(|e| format!("cannot write {e}"))
}

/// The energy change of a run (its drift when nothing adds or takes energy):
/// `(E(t) - E(0)) / |E(0)|`, or `E(t) - E(0)` in J when `E(0)` is about zero (below 1e-9 J or
/// a millionth of the largest |E|). Returns the values (one series), the series' name and the
/// axis title.
pub fn energy_drift(energy: &[f64]) -> (Vec<Vec<f64>>, &'static str, &'static str) {
    let e0 = energy.first().copied().unwrap_or(0.0);
    let largest = energy.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    if e0.abs() > 1e-9 && e0.abs() > 1e-6 * largest {
        let values = energy.iter().map(|e| vec![(e - e0) / e0.abs()]).collect();
        (
            values,
            "(E - E0) / |E0|",
            "relative energy change (E - E0) / |E0|",
        )
    } else {
        let values = energy.iter().map(|e| vec![e - e0]).collect();
        (values, "E - E0", "energy change E - E0 (J)")
    }
}

/// The columns `cols` of every sample.
pub fn columns(values: &[Vec<f64>], cols: std::ops::Range<usize>) -> Vec<Vec<f64>> {
    values.iter().map(|v| v[cols.clone()].to_vec()).collect()
}

/// Writes the figures, each to its file.
pub fn write_all(figures: &[(PathBuf, Figure)]) -> Result<(), String> {
    figures.iter().try_for_each(|(path, fig)| write(path, fig))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_come_from_the_extension() {
        assert_eq!(Format::of(Path::new("a/b.svg")), Ok(Format::Svg));
        assert_eq!(Format::of(Path::new("b.PNG")), Ok(Format::Png));
        for bad in ["b.pdf", "b", "b.svg.txt"] {
            let e = Format::of(Path::new(bad)).unwrap_err();
            assert!(e.contains(bad) && e.contains(".svg or .png"), "{e}");
        }
        assert_eq!(
            sibling(Path::new("run/ur5.png"), "energy"),
            Path::new("run/ur5-energy.png")
        );
    }

    #[test]
    fn units_follow_the_joints() {
        assert_eq!(unit(&[true, true], "rad", "m"), "rad");
        assert_eq!(unit(&[false], "rad", "m"), "m");
        assert_eq!(unit(&[true, false], "N m", "N"), "N m or N");
    }

    #[test]
    fn energy_is_relative_unless_it_starts_at_zero() {
        let (v, name, label) = energy_drift(&[-2.0, -1.0, -3.0]);
        assert_eq!(v, [[0.0], [0.5], [-0.5]]);
        assert_eq!(name, "(E - E0) / |E0|");
        assert!(label.starts_with("relative"));
        let (v, name, label) = energy_drift(&[1e-12, 2.0, 1.0]);
        assert_eq!(v[1], [2.0 - 1e-12]);
        assert_eq!(name, "E - E0");
        assert!(label.ends_with("(J)"));
    }

    #[test]
    fn ticks_have_the_decimals_they_need() {
        assert_eq!(tick(0.2, 1.0, 1.0), "0.2");
        assert_eq!(tick(0.05, 0.3, 0.3), "0.05");
        assert_eq!(tick(0.10, 0.3, 0.3), "0.10");
        assert_eq!(tick(-2.0, 9.6, 6.0), "-2");
        assert_eq!(tick(5e-29, 1e-12, 1e-12), "0");
        assert_eq!(tick(-2.5e-13, 3e-13, 3e-13), "-2.50e-13");
        assert_eq!(tick(25.0, 2e-3, 25.0), "2.50e1");
    }
}
