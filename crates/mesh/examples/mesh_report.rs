//! What piezocontact sees in a Gmsh mesh: its cells, boundary groups and regions (the names a
//! scene file refers to), and the quality checks a run does before anything is assembled.
//!
//! Run: `cargo run --release -p mesh --example mesh_report -- FILE.msh` (MSH 4.1, ASCII or
//! binary). Without a file it reports a generated 8 x 4 rectangle.

use std::process::ExitCode;

fn main() -> ExitCode {
    let mesh = match std::env::args().nth(1) {
        Some(path) => match mesh::read_msh(&path) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        },
        None => mesh::rectangle_tri([0.0, 0.0], [2.0, 1.0], 8, 4),
    };
    println!(
        "{}D mesh: {} nodes, {} {} cells",
        mesh.dim,
        mesh.n_nodes(),
        mesh.n_cells(),
        mesh.kind.name()
    );
    let (lo, hi) = mesh.bounding_box();
    println!("bounding box: {:?} to {:?}", &lo[..mesh.dim], &hi[..mesh.dim]);
    for (name, group) in &mesh.boundaries {
        println!(
            "boundary group `{name}`: {} facets, {} nodes",
            group.n_facets(),
            group.nodes().len()
        );
    }
    for (name, cells) in &mesh.regions {
        println!("region `{name}`: {} cells", cells.len());
    }
    match mesh.check() {
        Ok(q) => {
            println!(
                "quality: measure {:.6e} in all, smallest cell {:.3e}; h from {:.3e} to {:.3e}; largest aspect ratio {:.2}",
                q.total_measure, q.min_measure, q.h_min, q.h_max, q.max_aspect
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("the mesh fails the checks: {e}");
            ExitCode::FAILURE
        }
    }
}
