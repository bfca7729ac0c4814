//! A load path's files: its time series (each written instant a `step-NNNN.vtu`, compressed,
//! encoded on a thread of its own while the next instant is solved; `path.pvd` their
//! collection), then the last instant's files and the path's own.

use super::vtu::{self, CompressedMesh};
use super::{files, mesh_arrays, FieldArrays, NamedValues, Outputs, SetWriter};
use crate::Error;
use problem::Solution;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

/// The files of a load path, written step by step ([`PathFiles::step`]: each written instant's
/// `step-NNNN.vtu`, a ParaView time series) and finished with the last instant's solution
/// ([`PathFiles::finish`]): the plan's files of the last instant, `path.csv` (one row per
/// instant), `path.pvd` (the series' collection), and `path.svg`/`.png` (the contact forces
/// against time, and the tangential force against the prescribed x displacement: friction's
/// loop).
///
/// A step's file holds the point data (`u`, `phi`, and the contact's status, pressure,
/// traction, gap and flux), and the cell data (stress, strain, D, E) where the scene asks for
/// it (`path.cell_fields`); its arrays are zlib-compressed, the mesh's compressed once for all
/// steps. One step is encoded at a time, on its own thread, while the path goes on.
pub struct PathFiles {
    series: Vec<(f64, String)>,
    cell_fields: bool,
    mesh: Option<Arc<CompressedMesh>>,
    pending: Option<JoinHandle<(String, Vec<u8>)>>,
    /// Seconds the path waited on its steps' files while it ran.
    seconds: f64,
}

impl PathFiles {
    /// The files of `scene`'s path.
    pub fn new(scene: &problem::Scene) -> Self {
        PathFiles {
            series: vec![],
            cell_fields: scene.path.as_ref().is_some_and(|p| p.cell_fields),
            mesh: None,
            pending: None,
            seconds: 0.0,
        }
    }

    /// The names a path's set is sure to hold (checked before anything is written): its steps'
    /// files, the path's own, and the last instant's report, solution and contact table.
    pub fn expected_names(scene: &problem::Scene) -> Vec<String> {
        let steps = scene.path.as_ref().map_or(1, |p| p.instants().len());
        let written = |k: &usize| scene.path.as_ref().is_none_or(|p| p.has_fields(*k, steps));
        let mut names: Vec<String> = (0..steps).filter(written).map(step_name).collect();
        names.extend(["path.csv", "path.pvd", "run.json", "solution.vtu", "contact.csv"].map(String::from));
        names
    }

    /// Starts one instant's `step-NNNN.vtu` (written by the next step or by
    /// [`PathFiles::finish`]), after writing the one before into the set.
    ///
    /// # Errors
    /// [`Error::Output`] where the step before cannot be written.
    pub fn step(&mut self, step: &problem::Step<'_>, writer: &mut SetWriter) -> Result<(), Error> {
        let Some(f) = &step.fields else {
            return Ok(());
        };
        let started = Instant::now();
        self.flush(writer)?;
        let mesh = self
            .mesh
            .get_or_insert_with(|| {
                let (points, connectivity, offsets, cell_type) = mesh_arrays(step.mesh);
                Arc::new(CompressedMesh::new(&points, (&connectivity, &offsets), cell_type))
            })
            .clone();
        let cells = self.cell_fields.then_some(f.fields);
        let data = FieldArrays::new(step.mesh, (f.u, f.phi), cells, Some(step.contact)).into_owned();
        let name = step_name(step.row.step);
        self.series.push((step.row.t, name.clone()));
        self.pending = Some(std::thread::spawn(move || {
            let point: Vec<_> = data.point.iter().map(NamedValues::array).collect();
            let cell: Vec<_> = data.cell.iter().map(NamedValues::array).collect();
            (name, vtu::write_compressed(&mesh, &point, &cell))
        }));
        self.seconds += started.elapsed().as_secs_f64();
        Ok(())
    }

    /// Writes the step being encoded, if any, into the set.
    fn flush(&mut self, writer: &mut SetWriter) -> Result<(), Error> {
        let Some(pending) = self.pending.take() else {
            return Ok(());
        };
        let (name, bytes) = pending.join().map_err(|_| Error::Picture {
            name: "a step's file".into(),
            message: "its encoding thread panicked".into(),
        })?;
        writer.write(&name, &bytes)
    }

    /// The files of the last instant and the path's own, after the last step's file is
    /// written; the time spent on the steps' files is booked in `last`'s report as
    /// `timings_s.output`, and what of it the path waited while it ran is taken out of the
    /// contact and solve stages, whose clocks ran then (the last step's, written after the
    /// path, is not).
    ///
    /// # Errors
    /// As [`files`], and [`Error::Output`] where the last step's file cannot be written.
    pub fn finish(mut self, last: &mut Solution, writer: &mut SetWriter) -> Result<Outputs, Error> {
        let started = Instant::now();
        self.flush(writer)?;
        let t = &mut last.report.timings_s;
        t.output += self.seconds + started.elapsed().as_secs_f64();
        t.contact = (t.contact - self.seconds).max(0.0);
        t.solve = (t.solve - self.seconds).max(0.0);
        let mut out = files(last)?;
        if !self.series.is_empty() {
            out.add("path.pvd", pvd(&self.series));
        }
        Ok(out)
    }
}

/// The name of a path's instant `k` in its series.
fn step_name(k: usize) -> String {
    format!("step-{k:04}.vtu")
}

/// `path.pvd`: ParaView's collection of the steps' files, each at its instant.
fn pvd(series: &[(f64, String)]) -> Vec<u8> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, name) in series {
        s.push_str(&format!(
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{name}\"/>\n"
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s.into_bytes()
}
