//! Runs of the program in a child process, with a time limit: the stability study's cases and
//! the hostile inputs each run alone, so that a crash or a hang cannot take the study down and
//! a case's peak memory is its own.

use std::process::{Command, Stdio};
use std::time::Duration;

/// Runs `cmd` to its end, or kills it after `limit`; its stdout and stderr are collected.
pub fn run_with_limit(mut cmd: Command, limit: Duration) -> std::io::Result<std::process::Output> {
    use std::io::Read;
    let mut child = cmd.stdout(Stdio::null()).stderr(Stdio::piped()).spawn()?;
    // stderr is drained on a thread, so that a chatty child never blocks on a full pipe
    let mut pipe = child.stderr.take().expect("stderr is piped");
    let reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = pipe.read_to_end(&mut buf);
        buf
    });
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if started.elapsed() >= limit {
            let _ = child.kill();
            break child.wait()?;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = reader.join().unwrap_or_default();
    Ok(std::process::Output {
        status,
        stdout: vec![],
        stderr,
    })
}
