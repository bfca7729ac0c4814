//! The pictures of a run, like the paper's Figures 2-6, as SVG and PNG: the deformed mesh,
//! the multipliers along the contact boundary, and the contours of the potential. Text uses
//! the DejaVu Sans font shipped in `assets/` (no system font is needed).

use crate::DriverError;
use contact::{ContactPoints, ContactSolution, Status};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

const FONT: &str = "sans-serif";
const SIZE: (u32, u32) = (960, 600);

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // the bytes are a valid TrueType font shipped with the crate
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, include_bytes!("../assets/DejaVuSans.ttf"));
    });
}

fn err(what: &str, e: impl std::fmt::Display) -> DriverError {
    DriverError::Output(format!("picture {what}: {e}"))
}

/// A drawing on an SVG area.
type DrawSvg<'a> = &'a dyn Fn(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>;
/// The same drawing on a bitmap area.
type DrawPng<'a> = &'a dyn Fn(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>;

/// Draws with `draw` into an SVG string and a PNG image.
fn render(name: &str, draw: DrawSvg<'_>, draw_png: DrawPng<'_>) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    register_font();
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&area).map_err(|e| err(name, e))?;
        area.present().map_err(|e| err(name, e))?;
    }
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw_png(&area).map_err(|e| err(name, e))?;
        area.present().map_err(|e| err(name, e))?;
    }
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, SIZE.0, SIZE.1);
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

macro_rules! both {
    ($name:expr, $f:expr) => {
        render($name, &|a| $f(a), &|a| $f(a))
    };
}

/// What the 2D pictures draw: triangles over nodes with 2D coordinates and in-plane
/// displacements. For a 2D run, the mesh itself; for a 3D run, the face `front` (y = lo)
/// seen in the x-z plane.
struct View {
    title: &'static str,
    tris: Vec<[usize; 3]>,
    xy: Vec<[f64; 2]>,
    uv: Vec<[f64; 2]>,
    outline: Vec<[usize; 2]>,
    labels: (&'static str, &'static str),
}

impl View {
    fn new(mesh: &mesh::Mesh, u: &[[f64; 3]]) -> Option<View> {
        if mesh.dim == 2 {
            return Some(View {
                title: "",
                tris: mesh.iter_cells().map(|c| [c[0], c[1], c[2]]).collect(),
                xy: mesh.points.iter().map(|p| [p[0], p[1]]).collect(),
                uv: u.iter().map(|v| [v[0], v[1]]).collect(),
                outline: mesh
                    .boundaries
                    .values()
                    .flat_map(|g| g.iter().map(|f| [f[0], f[1]]).collect::<Vec<_>>())
                    .collect(),
                labels: ("x", "y"),
            });
        }
        let face = mesh.boundaries.get("front")?;
        let tris: Vec<[usize; 3]> = face.iter().map(|f| [f[0], f[1], f[2]]).collect();
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for q in 0..3 {
                let (a, b) = (t[q].min(t[(q + 1) % 3]), t[q].max(t[(q + 1) % 3]));
                *edges.entry([a, b]).or_insert(0) += 1;
            }
        }
        Some(View {
            title: " (face y = lo, seen in x-z)",
            tris,
            xy: mesh.points.iter().map(|p| [p[0], p[2]]).collect(),
            uv: u.iter().map(|v| [v[0], v[2]]).collect(),
            outline: edges.into_iter().filter(|(_, k)| *k == 1).map(|(e, _)| e).collect(),
            labels: ("x", "z"),
        })
    }

    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let used: std::collections::BTreeSet<usize> = self.tris.iter().flatten().copied().collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for &v in &used {
            for k in 0..2 {
                lo[k] = lo[k].min(self.xy[v][k]);
                hi[k] = hi[k].max(self.xy[v][k]);
            }
        }
        (lo, hi)
    }
}

/// All pictures of a 2D run (3D runs get the multipliers along the contact face's middle line).
pub fn pictures(
    mesh: &mesh::Mesh,
    u: &[[f64; 3]],
    phi: &[f64],
    contact: Option<(&ContactPoints, &ContactSolution)>,
    electric: bool,
) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    let mut out = vec![];
    if let Some(view) = View::new(mesh, u) {
        out.extend(both!("deformed", |a| deformed(a, &view))?);
        if electric {
            out.extend(both!("potential", |a| potential(a, &view, phi))?);
        }
    }
    if let Some((p, s)) = contact {
        out.extend(both!("multipliers", |a| multipliers(a, p, s))?);
    }
    Ok(out)
}

/// The axes of a picture of a [`View`]: caption, ranges, axis names, no grid.
fn view_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    labels: (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 20))
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(x, y)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(labels.0)
        .y_desc(labels.1)
        .label_style((FONT, 14))
        .draw()
        .map_err(e)?;
    Ok(chart)
}

fn deformed<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, view: &View) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let (lo, hi) = view.bounds();
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let umax = view
        .tris
        .iter()
        .flatten()
        .map(|&v| (view.uv[v][0].powi(2) + view.uv[v][1].powi(2)).sqrt())
        .fold(0.0f64, f64::max);
    let scale = if umax > 0.0 { 0.1 * size / umax } else { 1.0 };
    let pad = 0.15 * size;
    let caption = format!("Deformed configuration{} (displacement x {scale:.3e})", view.title);
    let mut chart = view_chart(
        area,
        caption,
        lo[0] - pad..hi[0] + pad,
        lo[1] - pad..hi[1] + pad,
        view.labels,
    )?;
    chart
        .draw_series(view.outline.iter().map(|&[a, b]| {
            PathElement::new(
                vec![(view.xy[a][0], view.xy[a][1]), (view.xy[b][0], view.xy[b][1])],
                RGBColor(190, 190, 190),
            )
        }))
        .map_err(e)?;
    let step = (view.tris.len() / 20_000).max(1);
    let at = |v: usize| {
        (
            view.xy[v][0] + scale * view.uv[v][0],
            view.xy[v][1] + scale * view.uv[v][1],
        )
    };
    chart
        .draw_series(
            view.tris
                .iter()
                .step_by(step)
                .map(|t| PathElement::new(vec![at(t[0]), at(t[1]), at(t[2]), at(t[0])], BLUE.mix(0.6))),
        )
        .map_err(e)?;
    Ok(())
}

fn multipliers<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &ContactPoints,
    s: &ContactSolution,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let nt = s.lambda.tangential.len().checked_div(p.len()).unwrap_or(0);
    // in 3D: the points on the middle line y = y_mid of the contact face
    let mut idx: Vec<usize> = (0..p.len()).collect();
    if p.dim == 3 {
        let ys: Vec<f64> = p.position.iter().map(|x| x[1]).collect();
        let (ymin, ymax) = ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| (a.min(y), b.max(y)));
        let mid = 0.5 * (ymin + ymax);
        let best = ys.iter().map(|y| (y - mid).abs()).fold(f64::INFINITY, f64::min);
        idx.retain(|&i| ((ys[i] - mid).abs() - best).abs() < 1e-12);
    }
    idx.sort_by(|&a, &b| p.position[a][0].total_cmp(&p.position[b][0]));
    let x: Vec<f64> = idx.iter().map(|&i| p.position[i][0]).collect();
    let ln: Vec<f64> = idx.iter().map(|&i| s.lambda.normal[i]).collect();
    let lt: Vec<f64> = idx
        .iter()
        .map(|&i| if nt > 0 { s.lambda.tangential[i * nt] } else { 0.0 })
        .collect();
    let sb: Vec<f64> = idx.iter().map(|&i| p.friction[i] * s.lambda.normal[i]).collect();
    let (xmin, xmax) = (x.first().copied().unwrap_or(0.0), x.last().copied().unwrap_or(1.0));
    let ymax = ln
        .iter()
        .chain(&sb)
        .chain(&lt)
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(1e-300)
        * 1.1;
    let ymin = lt.iter().fold(0.0f64, |m, &v| m.min(v)) * 1.1;
    let mut chart = ChartBuilder::on(area)
        .caption(
            if p.dim == 3 {
                "Multipliers on the contact face's middle line"
            } else {
                "Multipliers along the contact boundary"
            },
            (FONT, 24),
        )
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(xmin..xmax.max(xmin + 1e-12), ymin.min(-0.05 * ymax)..ymax)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("x")
        .y_desc("multiplier")
        .label_style((FONT, 14))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(LineSeries::new(
            x.iter().copied().zip(ln.iter().copied()),
            RED.stroke_width(2),
        ))
        .map_err(e)?
        .label("lambda_n (pressure)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    if nt > 0 {
        chart
            .draw_series(LineSeries::new(
                x.iter().copied().zip(lt.iter().copied()),
                BLUE.stroke_width(2),
            ))
            .map_err(e)?
            .label(if nt > 1 {
                "lambda_t (first component)"
            } else {
                "lambda_t"
            })
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        chart
            .draw_series(LineSeries::new(
                x.iter().copied().zip(sb.iter().copied()),
                BLACK.mix(0.5),
            ))
            .map_err(e)?
            .label("F lambda_n (Coulomb bound)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    }
    let slip: Vec<(f64, f64)> = idx
        .iter()
        .zip(&x)
        .filter(|(&i, _)| s.status[i] == Status::Slip && nt > 0)
        .map(|(&i, &xx)| (xx, s.lambda.tangential[i * nt]))
        .collect();
    chart
        .draw_series(slip.into_iter().map(|pt| Circle::new(pt, 3, BLUE.filled())))
        .map_err(e)?
        .label("slipping point")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLUE.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::MiddleMiddle)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    Ok(())
}

fn potential<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, view: &View, phi: &[f64]) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let (lo, hi) = view.bounds();
    let (pmin, pmax) = view
        .tris
        .iter()
        .flatten()
        .map(|&v| phi[v])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let span = if pmax > pmin { pmax - pmin } else { 1.0 };
    let caption = format!(
        "Electric potential{}: {pmin:.3e} (blue) to {pmax:.3e} (red), 12 contours",
        view.title
    );
    let mut chart = view_chart(area, caption, lo[0]..hi[0], lo[1]..hi[1], view.labels)?;
    // blue -> white -> red
    let color = |v: f64| {
        let t = ((v - pmin) / span).clamp(0.0, 1.0);
        if t < 0.5 {
            let s = t / 0.5;
            RGBColor((255.0 * s) as u8, (255.0 * s) as u8, 255)
        } else {
            let s = (1.0 - t) / 0.5;
            RGBColor(255, (255.0 * s) as u8, (255.0 * s) as u8)
        }
    };
    let xy = |v: usize| (view.xy[v][0], view.xy[v][1]);
    chart
        .draw_series(view.tris.iter().map(|t| {
            let mean = t.iter().map(|&v| phi[v]).sum::<f64>() / 3.0;
            Polygon::new(t.iter().map(|&v| xy(v)).collect::<Vec<_>>(), color(mean).filled())
        }))
        .map_err(e)?;
    // isolines by marching triangles
    let levels = 12;
    let mut segments = vec![];
    for t in &view.tris {
        for l in 1..levels {
            let level = pmin + span * l as f64 / levels as f64;
            let mut cut = vec![];
            for q in 0..3 {
                let (a, b) = (t[q], t[(q + 1) % 3]);
                let (fa, fb) = (phi[a] - level, phi[b] - level);
                if (fa < 0.0) != (fb < 0.0) {
                    let s = fa / (fa - fb);
                    cut.push((
                        view.xy[a][0] + s * (view.xy[b][0] - view.xy[a][0]),
                        view.xy[a][1] + s * (view.xy[b][1] - view.xy[a][1]),
                    ));
                }
            }
            if cut.len() == 2 {
                segments.push(cut);
            }
        }
    }
    chart
        .draw_series(segments.into_iter().map(|s| PathElement::new(s, BLACK.mix(0.7))))
        .map_err(e)?;
    Ok(())
}

/// The sweep's picture, SVG and PNG.
pub fn sweep_pictures(param: &str, rows: &[crate::studies::SweepRow]) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    both!("sweep", |a| crate::studies::draw_sweep(a, param, rows))
}

/// One series of a log-log chart: its name and its `(x, y)` points (non-positive values are
/// drawn at the floor of the axis). A series with an empty name continues the previous one's
/// colour and legend entry.
pub type Series = (String, Vec<(f64, f64)>);

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// A log-log chart of `series` with markers and lines, titled, with axis labels.
fn draw_loglog<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let pts = series.iter().flat_map(|(_, p)| p.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in pts.clone() {
        if x > 0.0 && x.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
        }
        if y > 0.0 && y.is_finite() {
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
    let (y0, y1) = (y0.max(1e-17) / 3.0, y1 * 3.0 * (y1 / y0.max(1e-17)).powf(0.6).max(10.0));
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
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
    for (i, (name, p)) in series.iter().enumerate() {
        if i > 0 && !name.is_empty() {
            k += 1;
        }
        let color = PALETTE[k % PALETTE.len()];
        let p: Vec<(f64, f64)> = p.iter().map(|&(x, y)| (x, y.max(y0))).collect();
        let line = chart
            .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))
            .map_err(e)?;
        if !name.is_empty() {
            line.label(name.as_str())
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

/// A log-log chart as SVG and PNG, named `name`.
pub fn loglog(
    name: &str,
    title: &str,
    labels: (&str, &str),
    series: &[Series],
) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    both!(name, |a| draw_loglog(a, title, labels, series))
}

/// The three pictures of a convergence study: error against time (a line per strategy and
/// size, through its tolerances), discretisation error against h, iterations against h (a line
/// per strategy, at its tightest tolerance). Names start with `prefix`.
pub fn study_pictures(prefix: &str, s: &crate::convergence::Study) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    let mut strategies: Vec<&str> = vec![];
    for r in &s.rows {
        if !strategies.contains(&r.strategy.as_str()) {
            strategies.push(&r.strategy);
        }
    }
    let mut time = vec![];
    let mut iters = vec![];
    for st in &strategies {
        let rows: Vec<_> = s.rows.iter().filter(|r| r.strategy == *st).collect();
        let mut sizes: Vec<usize> = rows.iter().map(|r| r.n).collect();
        sizes.dedup();
        for (i, n) in sizes.iter().enumerate() {
            let mut p: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.n == *n)
                .map(|r| (r.seconds, r.error))
                .collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            // one colour per strategy; a line per size joins its tolerances
            time.push((if i == 0 { st.to_string() } else { String::new() }, p));
        }
        let tightest = rows.iter().map(|r| r.tol).fold(f64::INFINITY, f64::min);
        iters.push((
            st.to_string(),
            rows.iter()
                .filter(|r| r.tol == tightest)
                .map(|r| (r.h, r.iterations.max(1) as f64))
                .collect(),
        ));
    }
    let rates = s.rates();
    let label = match rates.last() {
        Some(r) => format!("tight runs (last order {:.2})", r.2),
        None => "tight runs".to_string(),
    };
    let err_h = vec![(label, s.tight.iter().map(|&(_, e, h)| (h, e)).collect())];
    let mut out = loglog(
        &format!("{prefix}-error-time"),
        &format!("{}: error against run time", s.scene),
        ("wall time of the run (s)", "error"),
        &time,
    )?;
    out.extend(loglog(
        &format!("{prefix}-error-h"),
        &format!("{}: discretisation error against h", s.scene),
        ("h", "error"),
        &err_h,
    )?);
    out.extend(loglog(
        &format!("{prefix}-iterations-h"),
        &format!("{}: iterations against h (tightest tolerance)", s.scene),
        ("h", "iterations"),
        &iters,
    )?);
    Ok(out)
}
