//! A load path's files: its time series (each written instant a `step-NNNN.vtu`, compressed,
//! encoded and written by threads kept for the path while it goes on; `path.pvd` their
//! collection), then the last instant's files and the path's own.

use super::vtu::{self, CompressedMesh};
use super::{files_but, mesh_arrays, run_json_of, FieldArrays, NamedValues, Outputs, SetWriter};
use crate::Error;
use problem::Output;
use problem::Solution;
use std::collections::VecDeque;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Instant;

/// Steps waiting to be encoded and written or being so, at most: as many as a path's written
/// instants solved together (up to 16), so that the path goes on with its next instants while
/// they are written (with four, it waited 0.65 s of its 4.2 s on them at `paper-cycle`
/// n = 256).
const ENCODING: usize = 16;

/// The bytes of the fields' copies held by the steps being encoded, at most (each holds its
/// point and cell data's copy until its file is written: 10 MB a step for a 2D mesh of
/// 130,000 nodes; a 3D mesh's cell data is larger).
const ENCODING_BYTES: usize = 256 << 20;

/// The files of a load path, written step by step ([`PathFiles::step`]: each written instant's
/// `step-NNNN.vtu`, a ParaView time series) and finished with the last instant's solution
/// ([`PathFiles::finish`]): the plan's files of the last instant, `path.csv` (one row per
/// instant), `path.pvd` (the series' collection), and `path.svg`/`.png` (the contact forces
/// against time, and the tangential force against the prescribed x displacement: friction's
/// loop).
///
/// A step's file holds the point data (`u`, `phi`, and the contact's status, pressure,
/// traction, gap and flux), and the cell data (stress, strain, D, E) where the scene asks for
/// it (`path.cell_fields`); its arrays in zlib blocks, deflated where they are mostly zeros
/// and stored where not (a field's mantissas do not compress), the mesh's made once for all
/// steps. Each step is encoded and written into the set's staging directory by one of a few
/// threads kept for the path while the path goes on, at most 16 waiting (the written
/// instants of a path come several together: their fields are solved together), and taken
/// into the set in order (the path's thread wrote them, 10 ms a step at `paper-cycle`
/// n = 256, while the next instants waited).
pub struct PathFiles {
    series: Vec<(f64, String)>,
    cell_fields: bool,
    mesh: Option<Arc<CompressedMesh>>,
    /// The threads that encode and write the steps, started at the first.
    encoders: Option<Encoders>,
    /// The steps being encoded, each with the bytes of its fields' copy.
    pending: VecDeque<(Receiver<Result<Encoded, Error>>, usize)>,
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
            encoders: None,
            pending: VecDeque::new(),
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

    /// Starts one instant's `step-NNNN.vtu` (encoded and written by one of the path's threads,
    /// taken into the set by a later step or by [`PathFiles::finish`]), after taking in the oldest
    /// being encoded while 16 are, or while their fields' copies and this step's would pass
    /// 256 MB.
    ///
    /// # Errors
    /// [`Error::Output`] where a step before cannot be written.
    pub fn step(&mut self, step: &problem::Step<'_>, writer: &mut SetWriter) -> Result<(), Error> {
        let Some(f) = &step.fields else {
            return Ok(());
        };
        let started = Instant::now();
        let cells = f.fields.filter(|_| self.cell_fields);
        let data = FieldArrays::new(step.mesh, (f.u, f.phi), cells, Some(step.contact)).into_owned();
        let held = data.bytes();
        while self.pending.len() >= ENCODING
            || (!self.pending.is_empty() && self.pending_bytes() + held > ENCODING_BYTES)
        {
            self.flush_one(writer)?;
        }
        let mesh = self
            .mesh
            .get_or_insert_with(|| {
                let (points, connectivity, offsets, cell_type) = mesh_arrays(step.mesh);
                Arc::new(CompressedMesh::new(&points, (&connectivity, &offsets), cell_type))
            })
            .clone();
        let name = step_name(step.row.step);
        self.series.push((step.row.t, name.clone()));
        let staged = writer.staged();
        let encoding = self.encoders.get_or_insert_with(Encoders::new).run(move || {
            let point: Vec<_> = data.point.iter().map(NamedValues::array).collect();
            let cell: Vec<_> = data.cell.iter().map(NamedValues::array).collect();
            let file = vtu::write_compressed(&mesh, &point, &cell);
            match staged {
                Some(staged) => staged
                    .write(&name, |w| file.write_to(w))
                    .map(|()| Encoded::Written(name)),
                None => Ok(Encoded::Bytes(name, file.to_bytes())),
            }
        });
        self.pending.push_back((encoding, held));
        self.seconds += started.elapsed().as_secs_f64();
        Ok(())
    }

    /// The bytes of the fields' copies the steps being encoded hold.
    fn pending_bytes(&self) -> usize {
        self.pending.iter().map(|(_, b)| b).sum()
    }

    /// Writes every step being encoded into the set, in order.
    fn flush(&mut self, writer: &mut SetWriter) -> Result<(), Error> {
        while !self.pending.is_empty() {
            self.flush_one(writer)?;
        }
        Ok(())
    }

    /// Writes the oldest step being encoded, if any, into the set.
    fn flush_one(&mut self, writer: &mut SetWriter) -> Result<(), Error> {
        let Some((pending, _)) = self.pending.pop_front() else {
            return Ok(());
        };
        let encoded = pending.recv().map_err(|_| Error::Picture {
            name: "a step's file".into(),
            message: "its encoding panicked".into(),
        })?;
        match encoded? {
            Encoded::Written(name) => writer.adopt(&name),
            Encoded::Bytes(name, bytes) => writer.write(&name, &bytes),
        }
    }

    /// The files of the last instant and the path's own, made while the last steps' files
    /// are written, and `run.json` once they are: the time spent on the steps' files is
    /// booked in `last`'s report as `timings_s.output`, and what of it the path waited while
    /// it ran is taken out of the contact and solve stages, whose clocks ran then (the last
    /// steps', written after the path, are not).
    ///
    /// # Errors
    /// As [`super::files`], and [`Error::Output`] where a step's file cannot be written.
    pub fn finish(mut self, last: &mut Solution, writer: &mut SetWriter) -> Result<Outputs, Error> {
        let started = Instant::now();
        // the last instant's files made while the last steps are written, run.json after them
        let mut out = files_but(last, Some(Output::RunJson))?;
        self.flush(writer)?;
        let t = &mut last.report.timings_s;
        t.output += self.seconds + started.elapsed().as_secs_f64();
        t.contact = (t.contact - self.seconds).max(0.0);
        t.solve = (t.solve - self.seconds).max(0.0);
        if last.report.plan.outputs.contains(&Output::RunJson) {
            out.add("run.json", run_json_of(last)?);
        }
        if !self.series.is_empty() {
            out.add("path.pvd", pvd(&self.series));
        }
        Ok(out)
    }
}

/// Threads kept for a path's steps, each taking the next job sent (a thread per step cost
/// the mapping of its stack and, at its end, the other core's TLB flushes: 4.5 % of the
/// samples of `paper-cycle` at n = 256 with 51 steps written).
struct Encoders {
    jobs: Option<Sender<Job>>,
    threads: Vec<JoinHandle<()>>,
}

/// A job of [`Encoders`].
type Job = Box<dyn FnOnce() + Send>;

impl Encoders {
    /// As many threads as the machine's cores, from 1 to 4 (each compresses its arrays'
    /// blocks on rayon's pool).
    fn new() -> Self {
        let n = std::thread::available_parallelism().map_or(1, |n| n.get().clamp(1, 4));
        let (jobs, queue) = channel::<Job>();
        let queue = Arc::new(Mutex::new(queue));
        let threads = (0..n)
            .map(|_| {
                let queue = Arc::clone(&queue);
                std::thread::spawn(move || loop {
                    let job = queue.lock().unwrap_or_else(PoisonError::into_inner).recv();
                    let Ok(job) = job else { break };
                    // a job that panics drops its sender: its receiver says so
                    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job));
                })
            })
            .collect();
        Encoders {
            jobs: Some(jobs),
            threads,
        }
    }

    /// Runs `f` on the next free thread; its result comes on the receiver (an error there:
    /// `f` panicked).
    fn run<T: Send + 'static>(&self, f: impl FnOnce() -> T + Send + 'static) -> Receiver<T> {
        let (done, result) = channel();
        if let Some(jobs) = &self.jobs {
            let _ = jobs.send(Box::new(move || {
                let _ = done.send(f());
            }));
        }
        result
    }
}

impl Drop for Encoders {
    /// The queue closed, the threads end after the jobs sent.
    fn drop(&mut self) {
        self.jobs.take();
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

/// A step's file as its thread leaves it: written into the set's staging directory, or its
/// bytes, for the set's writer to write, where the platform stages files in memory.
enum Encoded {
    Written(String),
    Bytes(String, Vec<u8>),
}

/// The name of a path's instant `k` in its series.
fn step_name(k: usize) -> String {
    format!("step-{k:04}.vtu")
}

/// `path.pvd`: ParaView's collection of the steps' files (`.vtu`, or a run on pieces'
/// `.pvtu`), each at its instant.
pub fn pvd(series: &[(f64, String)]) -> Vec<u8> {
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

#[cfg(test)]
mod tests {
    use super::Encoders;

    /// Each job's result comes on its own receiver, whichever thread ran it; a job that panics
    /// says so on its receiver and the threads go on with the next jobs; dropping the
    /// encoders waits for the jobs sent.
    #[test]
    fn jobs_come_back_on_their_receivers_and_a_panic_is_told() {
        let encoders = Encoders::new();
        let results: Vec<_> = (0..20u64)
            .map(|k| {
                encoders.run(move || {
                    assert!(k != 7, "job 7 fails");
                    (0..=k).sum::<u64>()
                })
            })
            .collect();
        for (k, r) in results.into_iter().enumerate() {
            let k = k as u64;
            match r.recv() {
                Ok(sum) => assert_eq!(sum, k * (k + 1) / 2),
                Err(_) => assert_eq!(k, 7),
            }
        }
        let done = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
        for _ in 0..8 {
            let done = std::sync::Arc::clone(&done);
            drop(encoders.run(move || {
                std::thread::sleep(std::time::Duration::from_millis(5));
                done.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            }));
        }
        drop(encoders);
        assert_eq!(done.load(std::sync::atomic::Ordering::SeqCst), 8);
    }
}
