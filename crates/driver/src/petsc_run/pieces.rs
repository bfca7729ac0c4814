//! The run in which no rank holds the whole mesh (issue 45): each rank solves on its piece
//! ([`distributed::solve_on_pieces`]) and writes its piece of the solution into the output
//! set rank 0 has begun (`solution-<rank>.vtu`, beside `solution.pvtu`); rank 0 writes the
//! rest from the gathered surfaces (the contact points, the face the pictures draw) and the
//! report's sums, and turns the directory to the set only once every rank has written: a
//! rank that fails leaves no set behind, and the previous one stays.

use super::driver_error;
use crate::DriverError;
use files::output::pieces::{files_beside_pieces, names_beside_pieces, piece_name, write_into, Piece};
use files::output::SetWriter;
use files::run::peak_memory_bytes;
use files::scene_file::Source;
use problem::{Output, Reporter, Scene, Solution};
use std::path::Path;

/// Solves `scene` on pieces and writes its set into `dir`. Collective; rank 0 returns the
/// solution as its files were made from (its mesh the gathered face of the pictures, its
/// contact every rank's points), the others `None`.
///
/// # Errors
/// As [`super::run_distributed`].
pub(super) fn run(
    scene: &Scene,
    source: &Source,
    dir: &Path,
    (petsc, limits): (&petsc::Petsc, problem::Limits),
    from: distributed::PieceMesh,
    reporter: &mut dyn Reporter,
) -> Result<Option<Solution>, DriverError> {
    let (rank, ranks) = (petsc.rank(), petsc.size());
    let s = distributed::solve_on_pieces(petsc, scene, from, limits, reporter).map_err(driver_error)?;
    let gathered = s.gathered(petsc, scene).map_err(driver_error)?;
    let (piece, pvtu) = piece_files(&s, rank, ranks);
    // rank 0 begins the set, and every rank learns where to write its piece
    let mut writer = None;
    let mut staging: Vec<u8> = vec![];
    let mut began = [1.0];
    if rank == 0 {
        let names = names_beside_pieces(&s.report.plan.outputs, ranks);
        let w = SetWriter::begin(dir, &names);
        began[0] = f64::from(u8::from(w.as_ref().is_ok_and(|w| w.staging().is_some())));
        if let Ok(w) = &w {
            staging = w
                .staging()
                .map_or(vec![], |p| p.as_os_str().as_encoded_bytes().to_vec());
            // (on Unix, a path's encoded bytes are its bytes)
        }
        writer = Some(w);
    }
    petsc.broadcast(&mut began)?;
    petsc.broadcast_bytes(&mut staging)?;
    if began[0] == 0.0 {
        return match writer {
            Some(Err(e)) => Err(e.into()),
            Some(Ok(_)) => Err(DriverError::Usage(
                "a run on pieces writes its set through a directory every rank can reach; this platform stages sets in memory".into(),
            )),
            None => Ok(None),
        };
    }
    let mut writer = writer.and_then(Result::ok);
    let wrote = match writer.as_mut() {
        Some(w) => w.write(&piece_name(rank), &piece),
        None => write_into(&path_of(&staging), &piece_name(rank), &piece),
    };
    let failed = petsc.sum(&[f64::from(u8::from(wrote.is_err()))])?[0];
    let peaks = petsc.all_gather(peak_memory_bytes())?;
    wrote?;
    let Some(mut w) = writer else {
        return Ok(None);
    };
    if failed > 0.0 {
        // the set is abandoned (dropped unfinished): the directory keeps its previous one
        return Err(DriverError::Usage(format!(
            "{failed} of the {ranks} ranks could not write their piece of the solution into the output set: nothing written"
        )));
    }
    for r in 1..ranks {
        w.adopt(&piece_name(r))?;
    }
    w.write("solution.pvtu", &pvtu)?;
    let Some(gathered) = gathered else {
        return Ok(None);
    };
    let solution = rank_0s_solution(gathered, source, peaks)?;
    for (name, bytes) in files_beside_pieces(&solution)? {
        w.write(&name, &bytes)?;
    }
    w.finish()?;
    Ok(Some(solution))
}

/// This rank's piece of the solution (with its own contact points) as a `.vtu`, and the
/// `.pvtu` naming the `ranks` pieces.
fn piece_files(s: &distributed::PieceSolution, rank: usize, ranks: usize) -> (Vec<u8>, Vec<u8>) {
    let own = s.contact.as_ref().map(|c| &c.on_piece);
    let ghost: Vec<bool> = s.piece.cell_rank.iter().map(|&r| r != rank).collect();
    Piece {
        mesh: &s.piece.mesh,
        fields: (&s.u, &s.phi),
        cells: &s.fields,
        contact: own,
        ghost: &ghost,
        node_id: &s.piece.global_node,
        cell_id: &s.piece.global_cell,
    }
    .files(ranks)
}

/// The solution rank 0 writes the rest of the set from: the gathered report with its source
/// and the ranks' peaks, the gathered contact, the gathered face `front` as its mesh.
fn rank_0s_solution(g: distributed::Gathered, source: &Source, peaks: Vec<u64>) -> Result<Solution, DriverError> {
    let mut report = g.report;
    report.scene.source = source.label.clone();
    report.memory.peak_bytes = peaks.first().copied().unwrap_or(0);
    if let Some(p) = report.petsc.as_mut() {
        p.peak_bytes_per_rank = peaks;
    }
    // the pictures of a box draw its face `front`; a mesh read has none planned, and its
    // solution's mesh is then left empty
    let pictures = report
        .plan
        .outputs
        .iter()
        .any(|o| matches!(o, Output::Deformed | Output::Potential));
    let (mesh, u, phi) = match g.front {
        Some(front) => front,
        None if !pictures => (mesh::Mesh::empty(report.plan.dim), vec![], vec![]),
        None => {
            return Err(DriverError::Usage(
                "a run on pieces of a body without the face `front` its pictures draw".into(),
            ))
        }
    };
    Ok(Solution {
        report,
        mesh,
        u,
        phi,
        fields: problem::CellFields {
            stress: vec![],
            electric_displacement: vec![],
            strain: vec![],
            electric_field: vec![],
            at_nodes: None,
        },
        contact: g.contact,
    })
}

/// The path whose bytes rank 0 sent.
#[cfg(unix)]
fn path_of(bytes: &[u8]) -> std::path::PathBuf {
    use std::os::unix::ffi::OsStrExt;
    Path::new(std::ffi::OsStr::from_bytes(bytes)).to_path_buf()
}

/// The path whose bytes rank 0 sent (never reached: sets are staged in memory here).
#[cfg(not(unix))]
fn path_of(bytes: &[u8]) -> std::path::PathBuf {
    std::path::PathBuf::from(String::from_utf8_lossy(bytes).into_owned())
}
