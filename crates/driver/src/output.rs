//! The files of a run, exactly those its plan lists (`run.json`, `solution.vtu`,
//! `contact.csv`, the pictures), and their writing as one set ([`Outputs`]): every file goes
//! to a temporary name in the output directory and is renamed only when all of them are
//! written; on any error nothing is left behind.

use crate::plots::{self, Mark, Panel, Series};
use crate::DriverError;
use problem::{ContactResult, Output, RunReport, Solution};
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// Files to write together, as one set that replaces the directory's previous set.
pub struct Outputs {
    dir: PathBuf,
    files: Vec<(String, Vec<u8>)>,
}

/// The file in an output directory that lists the files of its set (so that the next run knows
/// which files are ours to replace, and which are the user's).
const MANIFEST: &str = ".piezocontact-outputs";

/// The file names a run writes (for a directory written before manifests existed).
const KNOWN: &[&str] = &[
    "run.json",
    "solution.vtu",
    "contact.csv",
    "deformed.svg",
    "deformed.png",
    "multipliers.svg",
    "multipliers.png",
    "potential.svg",
    "potential.png",
];

impl Outputs {
    /// Files for directory `dir` (created on commit).
    pub fn new(dir: &Path) -> Self {
        Outputs {
            dir: dir.to_path_buf(),
            files: vec![],
        }
    }

    /// Adds a file's bytes.
    pub fn add(&mut self, name: &str, bytes: Vec<u8>) {
        self.files.push((name.to_string(), bytes));
    }

    /// Adds several files.
    pub fn extend(&mut self, files: plots::Files) {
        self.files.extend(files);
    }

    /// Writes the set, replacing the directory's previous set as a whole.
    ///
    /// Under an exclusive lock on the parent directory (so that two runs into one directory
    /// never mix their files), every file is written into a fresh hidden sibling directory,
    /// with a manifest of the set; then, where the directory holds only an earlier set of ours,
    /// the two directories are exchanged atomically (`renameat2` with `RENAME_EXCHANGE` on
    /// Linux; elsewhere two renames) and the old one removed. Where the directory also holds
    /// files that are not ours, those stay: the new files are renamed in one by one and the
    /// files of the earlier set that the new one lacks are removed. On any error, the staging
    /// directory is removed and the previous set is as it was; a staging directory left by a
    /// killed run is removed by the next.
    ///
    /// # Errors
    /// [`DriverError::Output`] naming the path that could not be created, written or renamed.
    pub fn commit(self) -> Result<(), DriverError> {
        let io = |what: &str, p: &Path, e: std::io::Error| DriverError::Output {
            what: format!("{what} {}", p.display()),
            source: e,
        };
        let name = self
            .dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .ok_or_else(|| {
                io(
                    "no directory name in",
                    &self.dir,
                    std::io::ErrorKind::InvalidInput.into(),
                )
            })?;
        let parent = match self.dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|e| io("cannot create", &parent, e))?;
        let lock = std::fs::File::open(&parent).map_err(|e| io("cannot open", &parent, e))?;
        lock.lock().map_err(|e| io("cannot lock", &parent, e))?;
        remove_stale(&parent, &name);
        let staging = parent.join(format!(".{name}.piezocontact-new-{}", std::process::id()));
        let staged = self.stage(&staging).map_err(|(p, e)| {
            let _ = std::fs::remove_dir_all(&staging);
            io("cannot write", &p, e)
        })?;
        let result = replace(&self.dir, &staging, &parent, &name, &staged);
        let _ = std::fs::remove_dir_all(&staging);
        result.map_err(|(p, e)| io("cannot replace", &p, e))
    }

    /// Writes every file and the manifest into a fresh `staging` directory; returns the names.
    fn stage(&self, staging: &Path) -> Result<Vec<String>, (PathBuf, std::io::Error)> {
        std::fs::create_dir(staging).map_err(|e| (staging.to_path_buf(), e))?;
        let mut names = vec![];
        for (name, bytes) in &self.files {
            let path = staging.join(name);
            std::fs::write(&path, bytes).map_err(|e| (path, e))?;
            names.push(name.clone());
        }
        let manifest = staging.join(MANIFEST);
        std::fs::write(&manifest, names.join("\n") + "\n").map_err(|e| (manifest, e))?;
        Ok(names)
    }
}

/// Removes the staging and retired directories of `name` in `parent` that a killed run left
/// (called under the lock, so no live run is writing them).
fn remove_stale(parent: &Path, name: &str) {
    let prefix = format!(".{name}.piezocontact-");
    for entry in std::fs::read_dir(parent).into_iter().flatten().flatten() {
        if entry.file_name().to_string_lossy().starts_with(&prefix) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// The files of `dir`'s current set: those its manifest lists (with the manifest), or, for a
/// directory written before manifests, the known output names present.
fn ours(dir: &Path) -> Vec<String> {
    match std::fs::read_to_string(dir.join(MANIFEST)) {
        Ok(text) => text
            .lines()
            .filter(|l| !l.is_empty())
            .map(String::from)
            .chain([MANIFEST.to_string()])
            .collect(),
        Err(_) => KNOWN.iter().map(|s| s.to_string()).collect(),
    }
}

/// Puts the staged set in place of `dir`'s.
fn replace(
    dir: &Path,
    staging: &Path,
    parent: &Path,
    name: &str,
    staged: &[String],
) -> Result<(), (PathBuf, std::io::Error)> {
    let err = |p: &Path| {
        let p = p.to_path_buf();
        move |e| (p, e)
    };
    if !dir.exists() {
        return std::fs::rename(staging, dir).map_err(err(dir));
    }
    let old = ours(dir);
    let present: Vec<String> = std::fs::read_dir(dir)
        .map_err(err(dir))?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if present.iter().all(|f| old.contains(f)) {
        // only our earlier set: exchange the directories
        let retired = parent.join(format!(".{name}.piezocontact-old-{}", std::process::id()));
        exchange(staging, dir, &retired).map_err(err(dir))?;
        // the old set is now at `staging`
        std::fs::rename(staging, &retired).map_err(err(&retired))?;
        let _ = std::fs::remove_dir_all(&retired);
        return Ok(());
    }
    // the user's files stay: ours are renamed in one by one, and the stale ones removed
    for f in staged.iter().map(String::as_str).chain([MANIFEST]) {
        std::fs::rename(staging.join(f), dir.join(f)).map_err(err(&dir.join(f)))?;
    }
    for f in old
        .iter()
        .filter(|f| present.contains(f) && !staged.contains(f) && f.as_str() != MANIFEST)
    {
        let _ = std::fs::remove_file(dir.join(f));
    }
    Ok(())
}

/// Exchanges two directories: atomically on Linux (`RENAME_EXCHANGE`); elsewhere, or on a file
/// system without it, by moving `b` to `aside`, `a` into its place, and the old `b` to `a`.
fn exchange(a: &Path, b: &Path, aside: &Path) -> std::io::Result<()> {
    #[cfg(target_os = "linux")]
    {
        use rustix::fs::{renameat_with, RenameFlags, CWD};
        if renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).is_ok() {
            return Ok(());
        }
    }
    std::fs::rename(b, aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(aside, a)
}

/// `run.json`: the report, pretty, its keys in sorted order.
///
/// # Errors
/// [`DriverError::Picture`] if serde cannot write it (it always can).
pub fn run_json(report: &RunReport) -> Result<Vec<u8>, DriverError> {
    let encode = |e: serde_json::Error| DriverError::Picture {
        name: "run.json".into(),
        message: e.to_string(),
    };
    let tree = serde_json::to_value(report).map_err(encode)?;
    serde_json::to_vec_pretty(&tree).map_err(encode)
}

/// The files of a solution, those its plan lists.
///
/// # Errors
/// [`DriverError::Picture`] where a file cannot be made.
pub fn files(solution: &Solution) -> Result<Outputs, DriverError> {
    let mut out = Outputs::new(Path::new(""));
    let missing = |what: &str| DriverError::Picture {
        name: what.into(),
        message: "the plan lists it, but the run has nothing to draw it from".into(),
    };
    for &output in &solution.report.plan.outputs {
        match output {
            Output::RunJson => out.add("run.json", run_json(&solution.report)?),
            Output::SolutionVtu => out.add("solution.vtu", vtu(solution)?),
            Output::ContactCsv => {
                let c = solution.contact.as_ref().ok_or_else(|| missing("contact.csv"))?;
                out.add("contact.csv", contact_csv(c));
            }
            Output::Multipliers => {
                let c = solution.contact.as_ref().ok_or_else(|| missing("multipliers"))?;
                out.extend(multipliers_picture(c)?);
            }
            Output::Deformed => {
                let pic = plots::mesh_view::deformed_picture(&solution.mesh, &solution.u)?;
                out.extend(pic.ok_or_else(|| missing("deformed"))?);
            }
            Output::Potential => {
                let pic = plots::mesh_view::potential_picture(&solution.mesh, &solution.u, &solution.phi)?;
                out.extend(pic.ok_or_else(|| missing("potential"))?);
            }
        }
    }
    Ok(out)
}

/// Writes the files of a solution into `dir`, as one set.
///
/// # Errors
/// As [`files`] and [`Outputs::commit`].
pub fn write(solution: &Solution, dir: &Path) -> Result<(), DriverError> {
    let mut out = files(solution)?;
    out.dir = dir.to_path_buf();
    out.commit()
}

/// The solution as a VTK XML unstructured grid: point data `u` (3 components), `phi`; cell
/// data `stress` (Voigt), `strain`, `electric_displacement`, `electric_field`; and, with
/// contact, point data `contact_status` (0 none, 1 stick, 2 slip, 3 separated).
fn vtu(solution: &Solution) -> Result<Vec<u8>, DriverError> {
    let (mesh, fields) = (&solution.mesh, &solution.fields);
    let points: Vec<f64> = mesh.points.iter().flatten().copied().collect();
    let k = mesh.kind.n_nodes();
    let connectivity: Vec<u64> = mesh.cells.iter().map(|&v| v as u64).collect();
    let offsets: Vec<u64> = (1..=mesh.n_cells()).map(|c| (c * k) as u64).collect();
    let ct = match mesh.kind {
        mesh::CellKind::Tri3 => CellType::Triangle,
        mesh::CellKind::Quad4 => CellType::Quad,
        mesh::CellKind::Tet4 => CellType::Tetra,
    };
    let dim = mesh.dim;
    let nv = if dim == 2 { 3 } else { 6 };
    let mut point = vec![
        Attribute::generic("u", 3).with_data(solution.u.iter().flatten().copied().collect::<Vec<f64>>()),
        Attribute::scalars("phi", 1).with_data(solution.phi.clone()),
    ];
    if let Some(c) = &solution.contact {
        let mut status = vec![0.0; mesh.n_nodes()];
        for (i, &node) in c.nodes.iter().enumerate() {
            status[node] = match c.solution.status[i] {
                contact::Status::Stick => 1.0,
                contact::Status::Slip => 2.0,
                contact::Status::Separated => 3.0,
            };
        }
        point.push(Attribute::scalars("contact_status", 1).with_data(status));
    }
    let cell = vec![
        Attribute::generic("stress", nv as u32).with_data(fields.stress.clone()),
        Attribute::generic("strain", nv as u32).with_data(fields.strain.clone()),
        Attribute::generic("electric_displacement", dim as u32).with_data(fields.electric_displacement.clone()),
        Attribute::generic("electric_field", dim as u32).with_data(fields.electric_field.clone()),
    ];
    let vtk = Vtk {
        version: Version::new((1, 0)),
        title: "piezocontact solution".into(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: points.into(),
            cells: Cells {
                cell_verts: VertexNumbers::XML { connectivity, offsets },
                types: vec![ct; mesh.n_cells()],
            },
            data: Attributes { point, cell },
        }),
    };
    let mut buf = Vec::new();
    vtk.write_xml(&mut buf).map_err(|e| DriverError::Picture {
        name: "solution.vtu".into(),
        message: e.to_string(),
    })?;
    Ok(buf)
}

/// One row per contact point: `x,y[,z],gap,u_n,u_t[,u_t2],lambda_n,lambda_t[,lambda_t2],status`;
/// the displacements are those of the final solution (a frictionless body slides: its `u_t`
/// is written too), the tangential multipliers 0 where the law carries none.
fn contact_csv(c: &ContactResult) -> Vec<u8> {
    let (points, sol, u) = (&c.points, &c.solution, &c.displacement);
    let dim = points.dim;
    let nt = sol.lambda.n_tangential();
    let mut s = String::new();
    s.push_str(if dim == 2 {
        "x,y,gap,u_n,u_t,lambda_n,lambda_t,status\n"
    } else {
        "x,y,z,gap,u_n,u_t,u_t2,lambda_n,lambda_t,lambda_t2,status\n"
    });
    for i in 0..points.len() {
        let mut row: Vec<String> = points.position[i][..dim].iter().map(|x| format!("{x:.12e}")).collect();
        row.push(format!("{:.12e}", points.gap[i]));
        row.push(format!("{:.12e}", u.normal[i]));
        for &ut in u.tangential_of(i) {
            row.push(format!("{ut:.12e}"));
        }
        row.push(format!("{:.12e}", sol.lambda.normal[i]));
        for q in 0..dim - 1 {
            row.push(format!(
                "{:.12e}",
                if nt > 0 { sol.lambda.tangential[i * nt + q] } else { 0.0 }
            ));
        }
        row.push(sol.status[i].name().to_string());
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s.into_bytes()
}

/// The multipliers along the contact boundary (in 3D, along the contact face's middle line
/// y = y_mid), like the paper's figures: `λ_n`, `λ_t` (first component), the Coulomb bound
/// `F λ_n`, and the sliding points.
fn multipliers_picture(c: &ContactResult) -> Result<plots::Files, DriverError> {
    let (p, s) = (&c.points, &c.solution);
    let nt = s.lambda.n_tangential();
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
    let along = |f: &dyn Fn(usize) -> f64| idx.iter().map(|&i| (p.position[i][0], f(i))).collect::<Vec<_>>();
    let mut series = vec![Series::line("lambda_n (pressure)", along(&|i| s.lambda.normal[i]))];
    if nt > 0 {
        let name = if nt > 1 {
            "lambda_t (first component)"
        } else {
            "lambda_t"
        };
        series.push(Series::line(name, along(&|i| s.lambda.tangential[i * nt])));
        series.push(Series {
            name: "slipping point".into(),
            points: idx
                .iter()
                .filter(|&&i| s.status[i] == contact::Status::Slip)
                .map(|&i| (p.position[i][0], s.lambda.tangential[i * nt]))
                .collect(),
            mark: Mark::Dots,
        });
        series.push(Series {
            name: "F lambda_n (Coulomb bound)".into(),
            points: along(&|i| p.friction[i] * s.lambda.normal[i]),
            mark: Mark::Reference,
        });
    }
    let title = if p.dim == 3 {
        "Multipliers on the contact face's middle line"
    } else {
        "Multipliers along the contact boundary"
    };
    let panel = Panel {
        title: title.into(),
        labels: ("x".into(), "multiplier".into()),
        series,
    };
    plots::panels("multipliers", &[panel])
}

/// Where a run writes by default: `out/<scene>/`, the scene's name made a safe single path
/// component (letters, digits, `-`, `_` and `.` kept, anything else `_`, no leading dot), so that
/// a name like `../x` or `/tmp/x` cannot write outside `out/`.
pub fn default_dir(scene_name: &str) -> PathBuf {
    let safe: String = scene_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let safe = safe.trim_start_matches('.');
    Path::new("out").join(if safe.is_empty() { "scene" } else { safe })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn commit(dir: &Path, files: &[(&str, &str)]) -> Result<(), DriverError> {
        let mut o = Outputs::new(dir);
        for (name, text) in files {
            o.add(name, text.as_bytes().to_vec());
        }
        o.commit()
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_failed_commit_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        // a file in a subdirectory that does not exist cannot be written
        assert!(commit(&target, &[("a.txt", "a"), ("nested/b.txt", "b")]).is_err());
        assert!(!target.exists());
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
        // and over an earlier set, the earlier set stays as it was
        commit(&target, &[("run.json", "1"), ("contact.csv", "1")]).unwrap();
        assert!(commit(&target, &[("run.json", "2"), ("nested/b.txt", "b")]).is_err());
        assert_eq!(std::fs::read_to_string(target.join("run.json")).unwrap(), "1");
        assert_eq!(listing(dir.path()), ["run"]);
    }

    #[test]
    fn a_new_set_replaces_the_old_as_a_whole_and_keeps_the_users_files() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        commit(
            &target,
            &[("run.json", "1"), ("contact.csv", "1"), ("multipliers.svg", "1")],
        )
        .unwrap();
        // a run without contact: its set has no contact.csv, and none is left behind
        commit(&target, &[("run.json", "2"), ("solution.vtu", "2")]).unwrap();
        assert_eq!(listing(&target), [MANIFEST, "run.json", "solution.vtu"]);
        assert_eq!(std::fs::read_to_string(target.join("run.json")).unwrap(), "2");
        // a file of the user's stays; ours are replaced, and the stale ones removed
        std::fs::write(target.join("notes.txt"), "mine").unwrap();
        commit(&target, &[("run.json", "3"), ("contact.csv", "3")]).unwrap();
        assert_eq!(listing(&target), [MANIFEST, "contact.csv", "notes.txt", "run.json"]);
        assert_eq!(std::fs::read_to_string(target.join("notes.txt")).unwrap(), "mine");
        // no staging or retired directory is left beside it
        assert_eq!(listing(dir.path()), ["run"]);
    }

    #[test]
    fn runs_into_one_directory_do_not_mix() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("run");
        let threads: Vec<_> = (0..8)
            .map(|k| {
                let target = target.clone();
                std::thread::spawn(move || {
                    let text = k.to_string();
                    let files: Vec<(&str, &str)> = if k % 2 == 0 {
                        vec![("run.json", &text), ("contact.csv", &text)]
                    } else {
                        vec![("run.json", &text), ("solution.vtu", &text)]
                    };
                    commit(&target, &files).unwrap();
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        // one set, whole: its files agree and the manifest lists exactly them
        let files = listing(&target);
        let manifest = std::fs::read_to_string(target.join(MANIFEST)).unwrap();
        let listed: Vec<&str> = manifest.lines().collect();
        assert_eq!(files.len(), listed.len() + 1, "{files:?} {listed:?}");
        let texts: Vec<String> = listed
            .iter()
            .map(|f| std::fs::read_to_string(target.join(f)).unwrap())
            .collect();
        assert!(texts.iter().all(|t| t == &texts[0]), "{texts:?}");
    }

    #[test]
    fn the_default_directory_stays_under_out() {
        assert_eq!(default_dir("paper"), Path::new("out/paper"));
        assert_eq!(default_dir("../x"), Path::new("out/_x"));
        assert_eq!(default_dir("/tmp/x"), Path::new("out/_tmp_x"));
        assert_eq!(default_dir(".."), Path::new("out/scene"));
    }
}
