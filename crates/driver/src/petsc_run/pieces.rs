//! The run in which no rank holds the whole mesh (issue 45): each rank solves on its piece
//! ([`distributed::solve_on_pieces`]) and writes its piece of the solution into the output
//! set rank 0 has begun (`solution-<rank>.vtu`, beside `solution.pvtu`); rank 0 writes the
//! rest from the gathered surfaces (the contact points, the face the pictures draw) and the
//! report's sums, and turns the directory to the set only once every rank has written: a
//! rank that fails leaves no set behind, and the previous one stays.

use super::driver_error;
use crate::DriverError;
use files::output::pieces::{
    files_beside_pieces, names_of_pieces, piece_file, piece_name, step_stem, write_into, Frames, Piece,
};
use files::output::pvd;
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
    // rank 0 begins the set before the solve (a path's instants are written as they come),
    // and every rank learns where to write its pieces
    let (mut writer, staging) = match begin(petsc, dir, &names_of_pieces(scene, ranks))? {
        Begun::Set(w, staging) => (w, staging),
        Begun::Not(e) => return e.map_or(Ok(None), Err),
    };
    let mut series = Series::default();
    let mut each = |step: distributed::PieceStep<'_>| {
        let written = series.frame(&step, (rank, ranks), (writer.as_mut(), &staging));
        written.map_err(|e| {
            distributed::DistributedError::from(problem::ProblemError::NoSolution {
                sought: "a path's step file",
                why: e.to_string(),
            })
        })
    };
    let solved = distributed::solve_path_on_pieces(petsc, scene, from, limits, reporter, &mut each);
    let s = solved.map_err(driver_error)?;
    let gathered = s.gathered(petsc, scene).map_err(driver_error)?;
    let (piece, pvtu) = piece_files(&s, rank, ranks);
    let wrote = match writer.as_mut() {
        Some(w) => w.write(&piece_name(rank), &piece),
        None => write_into(&staging, &piece_name(rank), &piece),
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
        for stem in &series.stems {
            w.adopt(&piece_file(stem, r))?;
        }
    }
    w.write("solution.pvtu", &pvtu)?;
    let Some(gathered) = gathered else {
        return Ok(None);
    };
    let solution = rank_0s_solution(gathered, source, peaks)?;
    // a contact's closed form is judged on the gathered points (a field solution's error was
    // heard with the solve)
    if let Some(e) = solution.report.exact.as_ref().filter(|e| !e.kind().is_field()) {
        reporter.event(&problem::Event::Exact {
            kind: e.kind(),
            what: e.error_name(),
            error: e.error(),
        });
    }
    for (name, bytes) in files_beside_pieces(&solution)? {
        w.write(&name, &bytes)?;
    }
    if !series.stems.is_empty() {
        w.write("path.pvd", &pvd(&series.collection))?;
    }
    w.finish()?;
    Ok(Some(solution))
}

/// How the set's beginning went, on every rank.
enum Begun {
    /// Begun: rank 0's writer (`None` on the others) and the staging directory every rank
    /// writes its pieces into.
    Set(Option<SetWriter>, std::path::PathBuf),
    /// Not begun: rank 0's error (`None` on the others, which stop without one).
    Not(Option<DriverError>),
}

/// Rank 0 begins the set in `dir` (`names` checked), and sends every rank its staging
/// directory. Collective.
fn begin(petsc: &petsc::Petsc, dir: &Path, names: &[String]) -> Result<Begun, DriverError> {
    let mut writer = None;
    let mut staging: Vec<u8> = vec![];
    let mut began = [1.0];
    if petsc.rank() == 0 {
        let w = SetWriter::begin(dir, names);
        began[0] = f64::from(u8::from(w.as_ref().is_ok_and(|w| w.staging().is_some())));
        if let Ok(w) = &w {
            // (on Unix, a path's encoded bytes are its bytes)
            staging = w
                .staging()
                .map_or(vec![], |p| p.as_os_str().as_encoded_bytes().to_vec());
        }
        writer = Some(w);
    }
    petsc.broadcast(&mut began)?;
    petsc.broadcast_bytes(&mut staging)?;
    if began[0] == 0.0 {
        return Ok(Begun::Not(match writer {
            Some(Err(e)) => Some(e.into()),
            Some(Ok(_)) => Some(DriverError::Usage(
                "a run on pieces writes its set through a directory every rank can reach; this platform stages sets in memory".into(),
            )),
            None => None,
        }));
    }
    Ok(Begun::Set(writer.and_then(Result::ok), path_of(&staging)))
}

/// A path's time series on pieces: each written instant's stem, and `path.pvd`'s entries.
#[derive(Default)]
struct Series {
    frames: Frames,
    stems: Vec<String>,
    collection: Vec<(f64, String)>,
}

impl Series {
    /// Writes this rank's piece of an instant the path writes (`step-NNNN-<rank>.vtu`, into
    /// the set on rank 0, into its staging directory on the others) and, on rank 0, its
    /// `step-NNNN.pvtu`.
    fn frame(
        &mut self,
        step: &distributed::PieceStep<'_>,
        (rank, ranks): (usize, usize),
        (writer, staging): (Option<&mut SetWriter>, &Path),
    ) -> Result<(), files::Error> {
        let Some(f) = &step.frame else {
            return Ok(());
        };
        let stem = step_stem(step.row.step);
        let piece = Piece {
            mesh: f.mesh,
            fields: (f.u, f.phi),
            cells: f.cells,
            contact: Some(f.contact),
            owner: (&f.piece.cell_rank, rank),
            node_id: &f.piece.global_node,
            cell_id: &f.piece.global_cell,
        };
        let (vtu, pvtu) = piece.frame(&mut self.frames, &stem, ranks);
        let name = piece_file(&stem, rank);
        match writer {
            Some(w) => {
                w.write(&name, &vtu)?;
                w.write(&format!("{stem}.pvtu"), &pvtu)?;
            }
            None => write_into(staging, &name, &vtu)?,
        }
        self.collection.push((step.row.t, format!("{stem}.pvtu")));
        self.stems.push(stem);
        Ok(())
    }
}

/// This rank's piece of the solution (with its own contact points) as a `.vtu`, and the
/// `.pvtu` naming the `ranks` pieces.
fn piece_files(s: &distributed::PieceSolution, rank: usize, ranks: usize) -> (Vec<u8>, Vec<u8>) {
    let own = s.contact.as_ref().map(|c| &c.on_piece);
    Piece {
        mesh: &s.piece.mesh,
        fields: (&s.u, &s.phi),
        cells: Some(&s.fields),
        contact: own,
        owner: (&s.piece.cell_rank, rank),
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
            out_of_plane: vec![],
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
