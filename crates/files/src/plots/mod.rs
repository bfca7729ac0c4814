//! Pictures as SVG and PNG, drawn from plain data: charts of named series of points (linear
//! axes, stacked panels; or log-log), and views of a triangle mesh (deformed, contours of a
//! nodal field) in [`mesh_view`]. They know no run, study or scene: the caller builds the
//! series. Text uses the DejaVu Sans font shipped in `assets/` (no system font is needed).
//!
//! Extreme values never stop a picture: non-finite points are left out, and an axis whose
//! data span no finite range gets a unit one.

pub mod mesh_view;

use crate::Error;
use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

pub(crate) const FONT: &str = "sans-serif";
pub(crate) const SIZE: (u32, u32) = (960, 600);

/// A picture's files: `(name.svg, bytes)` and `(name.png, bytes)`.
pub type Files = Vec<(String, Vec<u8>)>;

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // the bytes are a valid TrueType font shipped with the crate
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, include_bytes!("../../assets/DejaVuSans.ttf"));
    });
}

fn err(what: &str, e: impl std::fmt::Display) -> Error {
    Error::Picture {
        name: what.into(),
        message: e.to_string(),
    }
}

/// A drawing on an SVG area.
type DrawSvg<'a> = &'a dyn Fn(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>;
/// The same drawing on a bitmap area.
type DrawPng<'a> = &'a dyn Fn(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>;

/// Draws with `draw` into an SVG string and a PNG image.
pub(crate) fn render(name: &str, draw: DrawSvg<'_>, draw_png: DrawPng<'_>) -> Result<Files, Error> {
    render_sized(name, SIZE, draw, draw_png)
}

/// [`render`] at `size` pixels.
pub(crate) fn render_sized(
    name: &str,
    size: (u32, u32),
    draw: DrawSvg<'_>,
    draw_png: DrawPng<'_>,
) -> Result<Files, Error> {
    register_font();
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        draw(&area).map_err(|e| err(name, e))?;
        area.present().map_err(|e| err(name, e))?;
    }
    let mut rgb = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw_png(&area).map_err(|e| err(name, e))?;
        area.present().map_err(|e| err(name, e))?;
    }
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(|e| err(name, e))?;
        w.write_image_data(&rgb).map_err(|e| err(name, e))?;
    }
    Ok(vec![
        (format!("{name}.svg"), svg.into_bytes()),
        (format!("{name}.png"), png_bytes),
    ])
}

/// Renders one drawing function, generic over the backend, to both formats.
macro_rules! both {
    ($name:expr, $f:expr) => {
        crate::plots::render($name, &|a| $f(a), &|a| $f(a))
    };
}
pub(crate) use both;

/// Colours of the series, in order.
const PALETTE: [RGBColor; 6] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// A line through the points, in the series' colour.
    Line,
    /// A thin black dashed line over the others (a bound, a closed form).
    Reference,
    /// Dots at the points, in the colour of the series before it.
    Dots,
}

/// One named series of points. A series with an empty name continues the previous one's
/// colour and legend entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Its name in the legend.
    pub name: String,
    /// Its points.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub mark: Mark,
}

impl Series {
    /// A line through `points`.
    pub fn line(name: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points,
            mark: Mark::Line,
        }
    }

    /// A thin dashed line through `points`, drawn over the lines: a reference (a bound, a
    /// closed form).
    pub fn reference(name: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points,
            mark: Mark::Reference,
        }
    }
}

/// One chart with linear axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Its caption.
    pub title: String,
    /// The axes' names.
    pub labels: (String, String),
    /// What it draws.
    pub series: Vec<Series>,
}

/// A line of at most this many points is drawn with a dot at each.
const FEW_POINTS: usize = 40;

/// Beyond this magnitude values are clamped, so that no span overflows.
const LIMIT: f64 = 1e300;

/// The range of the finite `values` (clamped to `±LIMIT`), always holding 0, padded by a tenth
/// of its span (a range of width `max(1, |v|)` where all values are one `v`).
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let finite: Vec<f64> = values
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-LIMIT, LIMIT))
        .collect();
    let (a, b) = finite
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    // values of one sign that vary by a visible fraction of their size (a depth under force
    // control against the voltage): their own range, zero left out; round-off (a span below
    // 1e-6 of them) is drawn flat, at its size from zero
    let size = a.abs().max(b.abs());
    if a * b > 0.0 && b - a > 1e-6 * size && b - a < 0.2 * size {
        let pad = 0.1 * (b - a);
        return (a - pad, b + pad);
    }
    let (lo, hi) = finite.iter().fold((0.0f64, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    let span = hi - lo;
    if !(span > 0.0) {
        let w = 0.5 * lo.abs().max(1.0);
        return (lo - w, lo + w);
    }
    let pad = 0.1 * span;
    (if lo < 0.0 { lo - pad } else { lo }, hi + pad)
}

/// The range of the finite x values (clamped to `±LIMIT`; not padded, not forced to hold 0).
fn x_range(panels: &[Panel]) -> (f64, f64) {
    let xs = panels
        .iter()
        .flat_map(|p| p.series.iter().flat_map(|s| s.points.iter().map(|q| q.0)))
        .filter(|x| x.is_finite())
        .map(|x| x.clamp(-LIMIT, LIMIT));
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if lo < hi {
        (lo, hi)
    } else if lo.is_finite() {
        let w = 0.5 * lo.abs().max(1.0);
        (lo - w, lo + w)
    } else {
        (0.0, 1.0)
    }
}

/// The tick labels of an axis spanning `span`: plotters' own form (up to 5 decimals), in
/// scientific notation where the span is below 1e-3 or from 1e6 on (5 decimals would print
/// every tick of a small range as 0.0), and a tick within round-off of zero printed as `0`
/// (a grid line at -2e-18 was labelled -0.0).
fn tick(span: f64) -> impl Fn(&f64) -> String {
    let scientific = !(1e-3..1e6).contains(&span);
    move |&v: &f64| {
        let v = if v.abs() <= 1e-9 * span { 0.0 } else { v };
        if v == 0.0 {
            return "0".into();
        }
        if scientific {
            return format!("{v:.2e}");
        }
        plotters::data::float::FloatPrettyPrinter {
            allow_scientific: false,
            min_decimal: 1,
            max_decimal: 5,
        }
        .print(v)
    }
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, panel: &Panel, x: (f64, f64)) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let y = padded_range(panel.series.iter().flat_map(|s| s.points.iter().map(|q| q.1)));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 22))
        .margin(12)
        // the last x tick's label centred on the right edge: room for its half
        .margin_right(30)
        .x_label_area_size(38)
        .y_label_area_size(76)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    let (x_tick, y_tick) = (tick(x.1 - x.0), tick(y.1 - y.0));
    chart
        .configure_mesh()
        .x_desc(panel.labels.0.as_str())
        .y_desc(panel.labels.1.as_str())
        .x_label_formatter(&x_tick)
        .y_label_formatter(&y_tick)
        .label_style((FONT, 13))
        .draw()
        .map_err(e)?;
    // each series' colour (a series of dots takes the one before it); the references (closed
    // forms, bounds) drawn last, dashed, over the lines they are compared with
    let mut colours = Vec::with_capacity(panel.series.len());
    let mut k = 0;
    for (i, s) in panel.series.iter().enumerate() {
        if i > 0 && !s.name.is_empty() && s.mark != Mark::Dots {
            k += 1;
        }
        colours.push(PALETTE[k % PALETTE.len()]);
    }
    let order = (0..panel.series.len())
        .filter(|&i| panel.series[i].mark != Mark::Reference)
        .chain((0..panel.series.len()).filter(|&i| panel.series[i].mark == Mark::Reference));
    for i in order {
        let (s, color) = (&panel.series[i], colours[i]);
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|&(a, b)| (a.clamp(-LIMIT, LIMIT), b.clamp(-LIMIT, LIMIT)))
            .collect();
        // a line of few points shows them: the values computed, not what lies between
        let dotted = s.mark == Mark::Line && points.len() <= FEW_POINTS;
        // a series with nothing to draw (no point slips) has no entry in the legend
        let shown = !points.is_empty();
        let drawn = match s.mark {
            Mark::Line if dotted => {
                chart
                    .draw_series(points.iter().map(|&q| Circle::new(q, 3, color.filled())))
                    .map_err(e)?;
                chart.draw_series(LineSeries::new(points, color.stroke_width(2)))
            }
            Mark::Line => chart.draw_series(LineSeries::new(points, color.stroke_width(2))),
            Mark::Reference => chart.draw_series(DashedLineSeries::new(points, 7, 5, BLACK.stroke_width(1))),
            Mark::Dots => chart.draw_series(points.into_iter().map(|q| Circle::new(q, 3, color.filled()))),
        }
        .map_err(e)?;
        if !s.name.is_empty() && shown {
            let mark = s.mark;
            drawn
                .label(s.name.as_str())
                .legend(move |(x, y)| -> DynElement<'static, DB, (i32, i32)> {
                    match mark {
                        Mark::Dots => Circle::new((x + 10, y), 3, color.filled()).into_dyn(),
                        // dashed, as the reference is drawn
                        Mark::Reference => plotters::element::DashedPathElement::new(
                            vec![(x, y), (x + 20, y)],
                            7,
                            5,
                            BLACK.stroke_width(1),
                        )
                        .into_dyn(),
                        Mark::Line => PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)).into_dyn(),
                    }
                });
        }
    }
    let place = legend_place(panel, (x, y), chart.plotting_area().dim_in_pixel());
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(place)
        .draw()
        .map_err(e)
}

/// Where a panel's legend covers the least of its curves: of the plot's corners and the
/// middles of its sides, the place whose box (sized by the named series and their longest
/// name, in pixels of a plot `size`) holds the fewest samples of the lines and points, the
/// upper right first among equals. (A legend at one fixed place covered a curve's end.)
fn legend_place(panel: &Panel, (x, y): ((f64, f64), (f64, f64)), size: (u32, u32)) -> SeriesLabelPosition {
    let (w, h) = (f64::from(size.0), f64::from(size.1));
    let named: Vec<&Series> = panel.series.iter().filter(|s| !s.name.is_empty()).collect();
    let longest = named.iter().map(|s| s.name.chars().count()).max().unwrap_or(0) as f64;
    // the box, with plotters' margin about it: 13 px text, an entry per line, the mark before it
    let (bw, bh) = (longest * 7.5 + 60.0, named.len() as f64 * 20.0 + 30.0);
    let to_px = |(a, b): (f64, f64)| ((a - x.0) / (x.1 - x.0) * w, (1.0 - (b - y.0) / (y.1 - y.0)) * h);
    let mut samples = vec![];
    for s in &panel.series {
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|q| q.0.is_finite() && q.1.is_finite())
            .map(|&q| to_px(q))
            .collect();
        samples.extend(pts.iter().copied());
        if s.mark != Mark::Dots {
            for seg in pts.windows(2) {
                samples.extend((1..8).map(|k| {
                    let t = f64::from(k) / 8.0;
                    (
                        seg[0].0 + t * (seg[1].0 - seg[0].0),
                        seg[0].1 + t * (seg[1].1 - seg[0].1),
                    )
                }));
            }
        }
    }
    let (left, middle, right) = (0.0, (w - bw) / 2.0, w - bw);
    let (top, centre, bottom) = (0.0, (h - bh) / 2.0, h - bh);
    let places = [
        (SeriesLabelPosition::UpperRight, right, top),
        (SeriesLabelPosition::UpperLeft, left, top),
        (SeriesLabelPosition::LowerRight, right, bottom),
        (SeriesLabelPosition::LowerLeft, left, bottom),
        (SeriesLabelPosition::MiddleRight, right, centre),
        (SeriesLabelPosition::MiddleLeft, left, centre),
        (SeriesLabelPosition::UpperMiddle, middle, top),
        (SeriesLabelPosition::LowerMiddle, middle, bottom),
    ];
    let covered = |&(_, x0, y0): &(SeriesLabelPosition, f64, f64)| {
        (samples.iter())
            .filter(|&&(a, b)| a >= x0 && a <= x0 + bw && b >= y0 && b <= y0 + bh)
            .count()
    };
    // the first of the least covered (min_by_key keeps the first among equals)
    (places.iter().min_by_key(|p| covered(p))).map_or(SeriesLabelPosition::UpperRight, |p| p.0.clone())
}

fn draw_panels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panels: &[Panel],
    shared: bool,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let x = x_range(panels);
    for (sub, panel) in area.split_evenly((panels.len().max(1), 1)).iter().zip(panels) {
        let x = if shared {
            x
        } else {
            x_range(std::slice::from_ref(panel))
        };
        draw_panel(sub, panel, x)?;
    }
    Ok(())
}

/// Panels with linear axes stacked in one picture, sharing their x range, as SVG and PNG
/// named `name`.
///
/// # Errors
/// [`Error::Picture`] where plotters cannot draw.
pub fn panels(name: &str, panels: &[Panel]) -> Result<Files, Error> {
    render_sized(name, stacked(panels.len()), &|a| draw_panels(a, panels, true), &|a| {
        draw_panels(a, panels, true)
    })
}

/// The size of a picture of `n` stacked panels: the standard width, and a height that gives
/// each panel room for its title, ticks and labels (260 px each, at least the standard).
fn stacked(n: usize) -> (u32, u32) {
    (SIZE.0, SIZE.1.max(260 * n as u32))
}

/// Panels stacked in one picture as [`panels`] draws them, each on its own x range.
///
/// # Errors
/// As [`panels`].
pub fn panels_apart(name: &str, panels: &[Panel]) -> Result<Files, Error> {
    render_sized(name, stacked(panels.len()), &|a| draw_panels(a, panels, false), &|a| {
        draw_panels(a, panels, false)
    })
}

/// A log-log chart of `series` with markers and lines.
fn draw_loglog<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let positive = |v: f64| v > 0.0 && v <= LIMIT;
    let pts = series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in pts {
        if positive(x) {
            x0 = x0.min(x);
            x1 = x1.max(x);
        }
        if positive(y) {
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if !(x1 > 0.0) {
        (x0, x1) = (1.0, 10.0);
    }
    if !(y1 > 0.0) {
        (y0, y1) = (1e-16, 1.0);
    }
    let (x0, x1) = (x0 / 1.5, x1 * 1.5);
    // room above the data for the legend
    let (y0, y1) = (
        y0.max(1e-17) / 3.0,
        (y1 * 3.0 * (y1 / y0.max(1e-17)).powf(0.6).max(10.0)).min(1e305),
    );
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(log_axis(x0, x1), log_axis(y0, y1))
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .label_style((FONT, 13))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(e)?;
    let mut k = 0;
    for (i, s) in series.iter().enumerate() {
        if i > 0 && !s.name.is_empty() {
            k += 1;
        }
        let color = PALETTE[(k + 1) % PALETTE.len()];
        let p: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|(x, y)| positive(*x) && !y.is_nan())
            .map(|&(x, y)| (x, y.clamp(y0, y1)))
            .collect();
        let line = chart
            .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))
            .map_err(e)?;
        if !s.name.is_empty() {
            line.label(s.name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        }
        chart
            .draw_series(p.iter().map(|&q| Circle::new(q, 4, color.filled())))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)?;
    Ok(())
}

/// A log axis over `lo..hi` with its marks: labelled at 1, 2 and 5 times the powers of ten
/// where it spans at most 2 decades, at the powers of ten (every few where there are more than
/// 8) beyond, and fine lines at each integer multiple up to 8 decades. Plotters' own marks start
/// at the first power of ten in the range (a range from 0.04 to 1.5 had none below 0.1) and
/// crowd their labels at the top of a decade ("8e-19e-11e0").
fn log_axis(lo: f64, hi: f64) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_marks(lo, hi);
    (lo..hi).log_scale().with_key_points(bold).with_light_points(light)
}

/// The labelled and the fine marks of [`log_axis`].
fn log_marks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = (hi / lo).log10();
    let inside = |v: &f64| (lo..=hi).contains(v);
    let multiples = |ms: &[f64], step: i32| -> Vec<f64> {
        (first..=last)
            .filter(|k| k.rem_euclid(step) == 0)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(inside)
            .collect()
    };
    let bold = if decades <= 2.0 {
        multiples(&[1.0, 2.0, 5.0], 1)
    } else {
        multiples(&[1.0], (decades / 8.0).ceil().max(1.0) as i32)
    };
    let light = if decades <= 8.0 {
        multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1)
    } else {
        multiples(&[1.0], 1)
    };
    (bold, light)
}

/// A log-log chart as SVG and PNG, named `name`. Points with a non-positive or non-finite x
/// are left out; y is clamped to the axis.
///
/// # Errors
/// [`Error::Picture`] where plotters cannot draw.
pub fn loglog(name: &str, title: &str, labels: (&str, &str), series: &[Series]) -> Result<Files, Error> {
    both!(name, |a| draw_loglog(a, title, labels, series))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legend goes where it covers the least: a curve rising to the upper right leaves the
    /// upper left free; one that fills the top sends it down.
    #[test]
    fn the_legend_goes_where_it_covers_least() {
        let panel = |points: Vec<(f64, f64)>| Panel {
            title: "t".into(),
            labels: ("x".into(), "y".into()),
            series: vec![Series::line("a long series name", points)],
        };
        let rising = panel((0..=20).map(|k| (f64::from(k), f64::from(k * k))).collect());
        let place = legend_place(&rising, ((0.0, 20.0), (0.0, 400.0)), (800, 500));
        assert!(matches!(place, SeriesLabelPosition::UpperLeft), "{place:?}");
        let top = panel(vec![(0.0, 1.0), (20.0, 1.0)]);
        let place = legend_place(&top, ((0.0, 20.0), (0.0, 1.0)), (800, 500));
        assert!(matches!(place, SeriesLabelPosition::LowerRight), "{place:?}");
    }

    /// Extreme values (infinite, NaN, 1e308) neither hang nor fail a picture.
    #[test]
    fn extreme_values_draw() {
        let wild = vec![(0.0, 1e308), (1.0, f64::INFINITY), (2.0, f64::NAN), (3.0, -1e308)];
        let panel = Panel {
            title: "wild".into(),
            labels: ("x".into(), "y".into()),
            series: vec![Series::line("a", wild.clone())],
        };
        assert_eq!(panels("wild", &[panel]).unwrap().len(), 2);
        assert_eq!(
            loglog("wild", "wild", ("x", "y"), &[Series::line("a", wild)])
                .unwrap()
                .len(),
            2
        );
        let empty = Panel {
            title: "empty".into(),
            labels: ("x".into(), "y".into()),
            series: vec![],
        };
        assert_eq!(panels("empty", &[empty]).unwrap().len(), 2);
    }

    /// A log axis is labelled inside its range, below its first power of ten too, at 1, 2
    /// and 5 times the powers over a short range and at some powers over a long one.
    #[test]
    fn log_axes_are_labelled_across_their_range() {
        let close =
            |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * y);
        let (bold, light) = log_marks(0.035, 1.5);
        assert!(close(&bold, &[0.05, 0.1, 0.2, 0.5, 1.0]), "{bold:?}");
        assert_eq!(light.len(), 6 + 9 + 1, "{light:?}");
        // 20 decades: every third power of ten
        let (bold, light) = log_marks(1e-17, 1e3);
        assert!(close(&bold, &[1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 1.0, 1e3]), "{bold:?}");
        assert_eq!(light.len(), 21);
        let (bold, _) = log_marks(2e-3, 5e2);
        assert!(close(&bold, &[1e-2, 1e-1, 1.0, 1e1, 1e2]), "{bold:?}");
    }
}
