//! The output set never loses a user's file (issue 20, class 4), through the program: `--out`
//! as `.`, `..`, a link to a directory, a directory of the user's files; a user's file named
//! like an output; runs killed at random instants of their commit; and the default paths of
//! the studies and the `fclib` command.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn exe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_piezocontact"))
}

fn run_in(cwd: &Path, args: &[&str]) -> Output {
    exe().current_dir(cwd).args(args).output().expect("the binary runs")
}

fn ok(o: &Output) -> &Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// The names a run of `paper` writes.
const SET: [&str; 9] = [
    "run.json",
    "solution.vtu",
    "contact.csv",
    "multipliers.svg",
    "multipliers.png",
    "deformed.svg",
    "deformed.png",
    "potential.svg",
    "potential.png",
];

fn paper(out: &str) -> Vec<String> {
    ["run", "paper", "--set", "mesh.n=8", "--out", out]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// The set in `dir` is one run's, whole: every file of it is there and reads.
fn whole_set(dir: &Path) {
    for f in SET {
        let bytes = std::fs::read(dir.join(f)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(f).display()));
        assert!(!bytes.is_empty(), "{f}");
    }
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("run.json")).unwrap()).unwrap();
    assert!(json["mesh"]["n_cells"].as_u64().unwrap() > 0);
}

#[test]
fn dot_dotdot_and_a_directory_of_the_users_files_are_written_into_and_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let here = tmp.path().join("work");
    std::fs::create_dir_all(here.join("sub")).unwrap();
    std::fs::write(here.join("notes.txt"), "mine").unwrap();
    std::fs::write(here.join("sub").join("data.csv"), "mine too").unwrap();
    ok(&run_in(&here, &args(&paper("."))));
    whole_set(&here);
    assert_eq!(std::fs::read_to_string(here.join("notes.txt")).unwrap(), "mine");
    // again: the set replaced, the user's files as they were
    ok(&run_in(&here, &args(&paper("."))));
    whole_set(&here);
    assert_eq!(
        std::fs::read_to_string(here.join("sub").join("data.csv")).unwrap(),
        "mine too"
    );
    // `..` from the subdirectory is the same directory; `DIR/.` too
    ok(&run_in(&here.join("sub"), &args(&paper(".."))));
    whole_set(&here);
    ok(&run_in(tmp.path(), &args(&paper("work/."))));
    whole_set(&here);
    // a name of 200 characters
    let long = "d".repeat(200);
    ok(&run_in(tmp.path(), &args(&paper(&long))));
    whole_set(&tmp.path().join(&long));
}

#[test]
fn a_linked_out_is_written_through_into_its_target() {
    let tmp = tempfile::tempdir().unwrap();
    let target = tmp.path().join("target");
    std::fs::create_dir(&target).unwrap();
    std::os::unix::fs::symlink(&target, tmp.path().join("link")).unwrap();
    ok(&run_in(tmp.path(), &args(&paper("link"))));
    assert!(std::fs::symlink_metadata(tmp.path().join("link"))
        .unwrap()
        .file_type()
        .is_symlink());
    whole_set(&target);
}

#[test]
fn a_users_file_named_like_an_output_is_never_replaced() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("contact.csv"), "my own table").unwrap();
    let o = run_in(tmp.path(), &args(&paper("out")));
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("contact.csv") && stderr.contains("nothing was written"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("contact.csv")).unwrap(),
        "my own table"
    );
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1, "nothing beside it");
    // a directory of the user's with an output's name
    std::fs::remove_file(out.join("contact.csv")).unwrap();
    std::fs::create_dir(out.join("solution.vtu")).unwrap();
    std::fs::write(out.join("solution.vtu").join("keep"), "k").unwrap();
    assert!(!run_in(tmp.path(), &args(&paper("out"))).status.success());
    assert_eq!(
        std::fs::read_to_string(out.join("solution.vtu").join("keep")).unwrap(),
        "k"
    );
}

/// Runs killed at instants spread over their length leave the directory with one whole set
/// (the previous one, or the new one), and the user's file as it was.
#[test]
fn a_kill_at_any_instant_leaves_one_whole_set() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    ok(&run_in(tmp.path(), &args(&paper("out"))));
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // the length of a run, to spread the kills over it
    let t0 = std::time::Instant::now();
    ok(&run_in(tmp.path(), &args(&paper("out"))));
    let length = t0.elapsed();
    for k in 0..16u32 {
        let mut child = exe()
            .current_dir(tmp.path())
            .args(args(&paper("out")))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(length * k / 16);
        let _ = child.kill();
        let _ = child.wait();
        whole_set(&out);
        assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    }
    // and the next run cleans what the killed ones left
    ok(&run_in(tmp.path(), &args(&paper("out"))));
    let sets = std::fs::read_dir(out.join(".piezocontact"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with("set-"))
        .count();
    assert_eq!(sets, 1);
}

#[test]
fn the_studies_default_paths_stay_under_out() {
    let tmp = tempfile::tempdir().unwrap();
    let scenes = tmp.path().join("elsewhere");
    std::fs::create_dir(&scenes).unwrap();
    let text = files::scene_file::SHIPPED
        .iter()
        .find(|(n, _)| *n == "paper")
        .unwrap()
        .1;
    std::fs::write(scenes.join("my scene.toml"), text).unwrap();
    let cwd = tmp.path().join("cwd");
    std::fs::create_dir(&cwd).unwrap();
    let o = run_in(
        &cwd,
        &[
            "sweep",
            "../elsewhere/my scene.toml",
            "--param",
            "load.p",
            "--from",
            "-1",
            "--to",
            "-2",
            "--steps",
            "2",
            "--set",
            "mesh.n=4",
        ],
    );
    ok(&o);
    let made: Vec<PathBuf> = std::fs::read_dir(cwd.join("out"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(made.len(), 1, "{made:?}");
    assert!(made[0].join("sweep.csv").exists());
    assert!(!scenes.join("my scene-sweep").exists());
}

#[test]
fn fclib_files_of_one_name_keep_their_own_csv_and_an_unsolved_file_fails_the_command() {
    let tmp = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../contact/tests/data/fclib");
    for d in ["a", "b"] {
        std::fs::create_dir(tmp.path().join(d)).unwrap();
    }
    std::fs::copy(data.join("FC3D_Example1.dat"), tmp.path().join("a/p.dat")).unwrap();
    std::fs::copy(data.join("FrictionContact3D_1c.dat"), tmp.path().join("b/p.dat")).unwrap();
    ok(&run_in(tmp.path(), &["fclib", "a/p.dat", "b/p.dat", "--out", "res"]));
    let (a, b) = (
        std::fs::read_to_string(tmp.path().join("res/p.csv")).unwrap(),
        std::fs::read_to_string(tmp.path().join("res/p-2.csv")).unwrap(),
    );
    assert_ne!(a, b);
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("res/summary.json")).unwrap()).unwrap();
    assert_eq!(summary[1]["csv"], "p-2.csv");
    // a file the solver cannot finish in its time: a non-zero exit, the file named
    let o = run_in(
        tmp.path(),
        &[
            "fclib",
            "a/p.dat",
            "--solver",
            "uzawa",
            "--tol",
            "1e-15",
            "--time-limit",
            "1e-9",
        ],
    );
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("files not solved") && stderr.contains("p.dat"),
        "{stderr}"
    );
}
