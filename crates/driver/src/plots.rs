//! The pictures of a run, like the paper's Figures 2-6, as SVG and PNG: the deformed mesh,
//! the multipliers along the contact boundary, and the contours of the potential. Text uses
//! the DejaVu Sans font shipped in `assets/` (no system font is needed).

use crate::DriverError;
use contact::{ContactPoints, ContactSolution, Status};
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

/// All pictures of a 2D run (3D runs get the multipliers along the contact face's middle line).
pub fn pictures(
    mesh: &mesh::Mesh,
    u: &[[f64; 3]],
    phi: &[f64],
    contact: Option<(&ContactPoints, &ContactSolution)>,
    electric: bool,
) -> Result<Vec<(String, Vec<u8>)>, DriverError> {
    let mut out = vec![];
    if mesh.dim == 2 {
        out.extend(both!("deformed", |a| deformed(a, mesh, u))?);
        if electric {
            out.extend(both!("potential", |a| potential(a, mesh, phi))?);
        }
    }
    if let Some((p, s)) = contact {
        out.extend(both!("multipliers", |a| multipliers(a, p, s))?);
    }
    Ok(out)
}

fn deformed<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mesh: &mesh::Mesh,
    u: &[[f64; 3]],
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let (lo, hi) = mesh.bounding_box();
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let umax = u
        .iter()
        .map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt())
        .fold(0.0f64, f64::max);
    let scale = if umax > 0.0 { 0.1 * size / umax } else { 1.0 };
    let pad = 0.15 * size;
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("Deformed configuration (displacement x {scale:.3e})"),
            (FONT, 24),
        )
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(lo[0] - pad..hi[0] + pad, lo[1] - pad..hi[1] + pad)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .label_style((FONT, 14))
        .draw()
        .map_err(e)?;
    // undeformed outline
    for g in mesh.boundaries.values() {
        for f in g.iter() {
            let pts: Vec<(f64, f64)> = f.iter().map(|&v| (mesh.points[v][0], mesh.points[v][1])).collect();
            chart
                .draw_series(std::iter::once(PathElement::new(pts, RGBColor(190, 190, 190))))
                .map_err(e)?;
        }
    }
    let step = (mesh.n_cells() / 20_000).max(1);
    chart
        .draw_series(mesh.iter_cells().step_by(step).map(|c| {
            let mut pts: Vec<(f64, f64)> = c
                .iter()
                .map(|&v| (mesh.points[v][0] + scale * u[v][0], mesh.points[v][1] + scale * u[v][1]))
                .collect();
            pts.push(pts[0]);
            PathElement::new(pts, BLUE.mix(0.6))
        }))
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

fn potential<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, mesh: &mesh::Mesh, phi: &[f64]) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let (lo, hi) = mesh.bounding_box();
    let (pmin, pmax) = phi
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let span = if pmax > pmin { pmax - pmin } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("Electric potential: {pmin:.3e} (blue) to {pmax:.3e} (red), 12 contours"),
            (FONT, 22),
        )
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(lo[0]..hi[0], lo[1]..hi[1])
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .label_style((FONT, 14))
        .draw()
        .map_err(e)?;
    let color = |v: f64| {
        let t = ((v - pmin) / span).clamp(0.0, 1.0);
        // blue -> white -> red
        if t < 0.5 {
            let s = t / 0.5;
            RGBColor((255.0 * s) as u8, (255.0 * s) as u8, 255)
        } else {
            let s = (1.0 - t) / 0.5;
            RGBColor(255, (255.0 * s) as u8, (255.0 * s) as u8)
        }
    };
    chart
        .draw_series(mesh.iter_cells().map(|c| {
            let pts: Vec<(f64, f64)> = c.iter().map(|&v| (mesh.points[v][0], mesh.points[v][1])).collect();
            let mean = c.iter().map(|&v| phi[v]).sum::<f64>() / c.len() as f64;
            Polygon::new(pts, color(mean).filled())
        }))
        .map_err(e)?;
    // isolines by marching triangles
    let levels = 12;
    let mut segments = vec![];
    for c in mesh.iter_cells() {
        for l in 1..levels {
            let level = pmin + span * l as f64 / levels as f64;
            let mut cut = vec![];
            for q in 0..3 {
                let (a, b) = (c[q], c[(q + 1) % 3]);
                let (fa, fb) = (phi[a] - level, phi[b] - level);
                if (fa < 0.0) != (fb < 0.0) {
                    let t = fa / (fa - fb);
                    cut.push((
                        mesh.points[a][0] + t * (mesh.points[b][0] - mesh.points[a][0]),
                        mesh.points[a][1] + t * (mesh.points[b][1] - mesh.points[a][1]),
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
