//! Views of a triangle mesh, like the paper's Figures 2-6: the deformed mesh and the contours
//! of a nodal field (the potential). A 2D mesh is drawn as it is; a 3D box by its face
//! `front` (y = lo), seen in the x-z plane.

use super::{both, Files, FONT};
use crate::Error;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// What the 2D pictures draw: triangles over nodes with 2D coordinates and in-plane
/// displacements. For a 2D run, the mesh itself; for a 3D run, the face `front` (y = lo)
/// seen in the x-z plane.
struct View {
    title: &'static str,
    tris: Vec<[usize; 3]>,
    /// The cell each triangle is drawn for (a 2D mesh's; `usize::MAX`, no cell, for a 3D
    /// face's).
    cell: Vec<usize>,
    xy: Vec<[f64; 2]>,
    uv: Vec<[f64; 2]>,
    outline: Vec<[usize; 2]>,
    labels: (String, String),
}

/// The triangles a triangle of `kind`'s order (a 2D cell, or a 3D cell's face) is drawn as
/// ([`mesh::CellKind::linear_triangles`]).
fn triangles(kind: mesh::CellKind, t: &[usize]) -> Vec<[usize; 3]> {
    kind.linear_triangles().iter().map(|p| p.map(|q| t[q])).collect()
}

/// The segments a boundary facet of a 2D mesh is drawn as: itself, or a three-node segment's
/// two halves.
fn segments(f: &[usize]) -> Vec<[usize; 2]> {
    match f.len() {
        3 => vec![[f[0], f[2]], [f[2], f[1]]],
        _ => vec![[f[0], f[1]]],
    }
}

impl View {
    fn new(mesh: &mesh::Mesh, u: &[[f64; 3]], units: &problem::Units) -> Option<View> {
        let axis = |name: &str| units.label(name, "length");
        if mesh.dim == 2 {
            let (cell, tris) = mesh
                .iter_cells()
                .enumerate()
                .flat_map(|(k, c)| triangles(mesh.kind, c).into_iter().map(move |t| (k, t)))
                .unzip();
            return Some(View {
                title: "",
                tris,
                cell,
                xy: mesh.points.iter().map(|p| [p[0], p[1]]).collect(),
                uv: u.iter().map(|v| [v[0], v[1]]).collect(),
                outline: mesh
                    .boundaries
                    .values()
                    .flat_map(|g| g.iter().flat_map(segments).collect::<Vec<_>>())
                    .collect(),
                labels: (axis("x"), axis("y")),
            });
        }
        let face = mesh.boundaries.get("front")?;
        let tris: Vec<[usize; 3]> = face.iter().flat_map(|f| triangles(mesh.kind, f)).collect();
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for q in 0..3 {
                let (a, b) = (t[q].min(t[(q + 1) % 3]), t[q].max(t[(q + 1) % 3]));
                *edges.entry([a, b]).or_insert(0) += 1;
            }
        }
        Some(View {
            title: " (face y = lo, seen in x-z)",
            cell: vec![usize::MAX; tris.len()],
            tris,
            xy: mesh.points.iter().map(|p| [p[0], p[2]]).collect(),
            uv: u.iter().map(|v| [v[0], v[2]]).collect(),
            outline: edges.into_iter().filter(|(_, k)| *k == 1).map(|(e, _)| e).collect(),
            labels: (axis("x"), axis("z")),
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

/// The deformed mesh (displacements magnified to a tenth of the body's size), as SVG and PNG
/// named `deformed`; `None` where the mesh has no view (a 3D mesh without a `front` face).
///
/// # Errors
/// [`Error::Picture`] where plotters cannot draw.
pub fn deformed_picture(mesh: &mesh::Mesh, u: &[[f64; 3]], units: &problem::Units) -> Result<Option<Files>, Error> {
    View::new(mesh, u, units)
        .map(|view| both!("deformed", |a| deformed(a, &view)))
        .transpose()
}

/// What a potential picture draws: a view, its nodal potential and unit, and which of the
/// view's triangles are grey (their cell carries no potential).
struct Drawn<'a> {
    view: &'a View,
    phi: &'a [f64],
    unit: &'a str,
    grey: Vec<bool>,
}

/// A part of a 2D body drawn close, below the whole (an indenter's contact zone, where the
/// whole body's picture shows it as a speck at its edge).
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    /// Its x range.
    pub x: std::ops::Range<f64>,
    /// Its y range.
    pub y: std::ops::Range<f64>,
    /// What it shows, in the caption (`near the tip, r/a ≤ 3`).
    pub what: String,
}

impl Window {
    fn holds(&self, p: [f64; 2]) -> bool {
        self.x.contains(&p[0]) && self.y.contains(&p[1])
    }
}

/// Filled contours of the nodal field `phi` with 12 isolines and a colour bar in the
/// potential's unit, as SVG and PNG named `potential`; with a `zone`, the cells within it
/// drawn close below the whole body, with contours and a colour bar of their own; the cells
/// that `electric` (by cell) says carry no potential drawn grey, out of the range and the
/// contours (a substrate under a film was white, as a potential of 0 is); `None` where the
/// mesh has no view.
///
/// # Errors
/// [`Error::Picture`] where plotters cannot draw.
pub fn potential_picture(
    mesh: &mesh::Mesh,
    (u, phi): (&[[f64; 3]], &[f64]),
    units: &problem::Units,
    (zone, electric): (Option<&Window>, Option<&[bool]>),
) -> Result<Option<Files>, Error> {
    let Some(view) = View::new(mesh, u, units) else {
        return Ok(None);
    };
    let grey = (view.cell.iter())
        .map(|&c| electric.is_some_and(|e| e.get(c) == Some(&false)))
        .collect();
    let drawn = Drawn {
        view: &view,
        phi,
        unit: units.of_quantity("potential"),
        grey,
    };
    let Some(zone) = zone.filter(|w| view.tris.iter().any(|t| t.iter().all(|&v| w.holds(view.xy[v])))) else {
        return both!("potential", |a| potential(a, &drawn, None)).map(Some);
    };
    let size = (super::SIZE.0, 2 * super::SIZE.1 - 100);
    super::render_sized("potential", size, &|a| whole_and_zone(a, &drawn, zone), &|a| {
        whole_and_zone(a, &drawn, zone)
    })
    .map(Some)
}

/// The whole body's potential above, the zone's below.
fn whole_and_zone<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    drawn: &Drawn<'_>,
    zone: &Window,
) -> Result<(), String> {
    let (_, h) = area.dim_in_pixel();
    let (whole, close) = area.split_vertically(h / 2);
    potential(&whole, drawn, None)?;
    potential(&close, drawn, Some(zone))
}

/// The axes of a picture of a [`View`]: caption, ranges, axis names, no grid; the ranges grown
/// along one axis so that a unit of x and of y are drawn the same length (the body's true
/// shape: a 2 x 1 block twice as wide as high).
fn view_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    labels: (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let (margin, x_labels, y_labels, caption_px) = (15u32, 35u32, 45u32, 34u32);
    let (w, h) = area.dim_in_pixel();
    let plot_w = w.saturating_sub(2 * margin + y_labels).max(1) as f64;
    let plot_h = h.saturating_sub(2 * margin + x_labels + caption_px).max(1) as f64;
    let (x, y) = equal_aspect(x, y, plot_w / plot_h);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 20))
        .margin(margin)
        .x_label_area_size(x_labels)
        .y_label_area_size(y_labels)
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

/// The ranges `x`, `y` grown about their centres so that their lengths stand as `aspect`
/// (the plotting area's width over its height): equal units along both axes.
fn equal_aspect(
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    aspect: f64,
) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let (dx, dy) = (x.end - x.start, y.end - y.start);
    if !(dx > 0.0 && dy > 0.0 && aspect > 0.0) {
        return (x, y);
    }
    let grow = |r: std::ops::Range<f64>, length: f64| {
        let c = 0.5 * (r.start + r.end);
        c - 0.5 * length..c + 0.5 * length
    };
    if dx / dy < aspect {
        (grow(x, dy * aspect), y)
    } else {
        (x, grow(y, dx / aspect))
    }
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
        (&view.labels.0, &view.labels.1),
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

fn potential<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    drawn: &Drawn<'_>,
    window: Option<&Window>,
) -> Result<(), String> {
    let Drawn { view, phi, unit, .. } = *drawn;
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    // the triangles drawn: all, or those wholly within the window; grey those of cells
    // without the potential
    let within = |t: &&[usize; 3]| window.is_none_or(|w| t.iter().all(|&v| w.holds(view.xy[v])));
    let shown = || view.tris.iter().enumerate().filter(|(_, t)| within(t));
    let grey: Vec<&[usize; 3]> = shown().filter(|&(k, _)| drawn.grey[k]).map(|(_, t)| t).collect();
    let tris: Vec<&[usize; 3]> = shown().filter(|&(k, _)| !drawn.grey[k]).map(|(_, t)| t).collect();
    let (lo, hi) = match window {
        Some(w) => ([w.x.start, w.y.start], [w.x.end, w.y.end]),
        None => view.bounds(),
    };
    let (pmin, pmax) = tris
        .iter()
        .copied()
        .flatten()
        .map(|&v| phi[v])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let span = if pmax > pmin { pmax - pmin } else { 1.0 };
    // a diverging map centred at zero: white at phi = 0, blue below, red above, at full
    // strength at the larger of |min| and |max|
    let reach = pmin.abs().max(pmax.abs());
    let reach = if reach > 0.0 { reach } else { 1.0 };
    let in_unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" [{unit}]")
    };
    let mut close = window.map_or(String::new(), |w| format!(" {}", w.what));
    if !grey.is_empty() {
        close.push_str(" (grey: no potential)");
    }
    let caption = format!(
        "Electric potential{in_unit}{}{close}: {pmin:.3e} to {pmax:.3e}, 12 contours",
        view.title
    );
    let (w, _) = area.dim_in_pixel();
    let (plot, bar) = area.split_horizontally(w.saturating_sub(146));
    let mut chart = view_chart(
        &plot,
        caption,
        lo[0]..hi[0],
        lo[1]..hi[1],
        (&view.labels.0, &view.labels.1),
    )?;
    let color = |v: f64| diverging(v / reach);
    colour_bar(&bar, (pmin, pmax), &color, unit)?;
    let xy = |v: usize| (view.xy[v][0], view.xy[v][1]);
    chart
        .draw_series(grey.iter().map(|t| {
            Polygon::new(
                t.iter().map(|&v| xy(v)).collect::<Vec<_>>(),
                RGBColor(215, 215, 215).filled(),
            )
        }))
        .map_err(e)?;
    chart
        .draw_series(tris.iter().map(|t| {
            let mean = t.iter().map(|&v| phi[v]).sum::<f64>() / 3.0;
            Polygon::new(t.iter().map(|&v| xy(v)).collect::<Vec<_>>(), color(mean).filled())
        }))
        .map_err(e)?;
    let segments = isolines(view, &tris, phi, (pmin, span));
    chart
        .draw_series(segments.into_iter().map(|s| PathElement::new(s, BLACK.mix(0.7))))
        .map_err(e)?;
    Ok(())
}

/// The 11 isolines of `phi` between `pmin` and `pmin + span` over the triangles `tris`, by
/// marching triangles: a segment per triangle and level that crosses it.
fn isolines(view: &View, tris: &[&[usize; 3]], phi: &[f64], (pmin, span): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let levels = 12;
    let mut segments = vec![];
    for t in tris {
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
    segments
}

/// The diverging map at `t` in [-1, 1]: blue at -1, white at 0, red at 1.
fn diverging(t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(-1.0, 1.0) } else { 0.0 };
    let s = (255.0 * (1.0 - t.abs())) as u8;
    if t < 0.0 {
        RGBColor(s, s, 255)
    } else {
        RGBColor(255, s, s)
    }
}

/// A vertical colour bar of `color` over the values `(lo, hi)`, with their ticks and `unit`.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    color: &dyn Fn(f64) -> RGBColor,
    unit: &str,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5 * lo.abs().max(1.0), lo + 0.5 * lo.abs().max(1.0))
    };
    let mut chart = ChartBuilder::on(area)
        .margin_top(49)
        .margin_bottom(50)
        .margin_left(12)
        .margin_right(16)
        // the labels right of the bar, left-aligned: a label a little wider than plotters
        // measures it runs into the free margin (right-aligned on its left, its end was cut)
        .right_y_label_area_size(84)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(e)?;
    let steps = 120;
    chart
        .draw_series((0..steps).map(|k| {
            let (a, b) = (
                lo + (hi - lo) * k as f64 / steps as f64,
                lo + (hi - lo) * (k + 1) as f64 / steps as f64,
            );
            Rectangle::new([(0.0, a), (1.0, b)], color(0.5 * (a + b)).filled())
        }))
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(7)
        .y_label_formatter(&|v| format!("{v:.2e}"))
        .y_desc(unit)
        .label_style((FONT, 12))
        .draw()
        .map_err(e)?;
    Ok(())
}
