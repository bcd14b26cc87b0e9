//! Durability of every file meshpaint writes, shown on the real binary's system calls: under
//! `strace`, a packed save, a glTF export and an autosave recovery write must each create a
//! new temporary file in the target's directory, write all the bytes to it, `fsync` it, rename
//! it onto the target, and then open and `fsync` the directory (so the rename itself survives
//! a power cut, not only a `kill -9`, which keeps the page cache and cannot tell).
//!
//! The checker is shown to fail: on `cp` (written in place, never synced), on `cat > tmp && mv`
//! (renamed but not synced) and on the real trace with the file's or the directory's `fsync`
//! removed. Needs `strace` (`bash .ci/run` installs it); a missing tool fails the test.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;
use common::{TempDir, model};

/// One system call of a trace: name, quoted string arguments, first integer argument, result.
#[derive(Debug, Clone)]
struct Call {
    name: String,
    strings: Vec<String>,
    first_int: Option<i64>,
    result: i64,
    line: String,
}

/// The quoted strings in `args`, in order (strace escapes are kept as they are).
fn quoted(args: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut chars = args.chars();
    while let Some(c) = chars.next() {
        if c == '"' {
            let mut text = String::new();
            let mut escaped = false;
            for c in chars.by_ref() {
                if escaped {
                    text.push(c);
                    escaped = false;
                } else if c == '\\' {
                    text.push(c);
                    escaped = true;
                } else if c == '"' {
                    break;
                } else {
                    text.push(c);
                }
            }
            out.push(text);
        }
    }
    out
}

/// Parses `strace -f` output, joining `<unfinished ...>` / `<... resumed>` halves.
fn parse(trace: &str) -> Vec<Call> {
    let mut pending: std::collections::HashMap<String, String> = std::collections::HashMap::new();
    let mut calls = Vec::new();
    for raw in trace.lines() {
        let (pid, rest) = raw.split_once(' ').unwrap_or(("", raw));
        let rest = rest.trim_start();
        let line = if let Some(head) = rest.strip_suffix("<unfinished ...>") {
            pending.insert(pid.to_owned(), head.to_owned());
            continue;
        } else if rest.starts_with("<... ") {
            let tail = rest.split_once("resumed>").map_or("", |(_, t)| t);
            format!("{}{tail}", pending.remove(pid).unwrap_or_default())
        } else {
            rest.to_owned()
        };
        let Some(open) = line.find('(') else { continue };
        // `name(args)   = result` (strace pads before the `=`).
        let Some(equals) = line.rfind(" = ") else { continue };
        let Some(close) = line[..equals].rfind(')').filter(|&close| close > open) else { continue };
        let name = line[..open].to_owned();
        let args = &line[open + 1..close];
        let result = line[equals + 3..].split_whitespace().next().and_then(|r| r.parse().ok()).unwrap_or(-1);
        let first_int = args.split(',').next().and_then(|a| a.trim().parse().ok());
        calls.push(Call { name, strings: quoted(args), first_int, result, line: line.clone() });
    }
    calls
}

/// Runs `command` under strace; returns its parsed trace.
fn traced(command: &mut Command, dir: &Path) -> Vec<Call> {
    let trace_file = dir.join("strace.txt");
    let program = command.get_program().to_owned();
    let args: Vec<_> = command.get_args().map(|a| a.to_owned()).collect();
    let output = Command::new("strace")
        .args(["-f", "-qq", "-s", "0", "-o"])
        .arg(&trace_file)
        .args(["-e", "trace=open,openat,creat,write,pwrite64,writev,fsync,fdatasync,close,rename,renameat,renameat2"])
        .arg("--")
        .arg(&program)
        .args(&args)
        .output()
        .expect("cannot run strace: install it (bash .ci/run does)");
    assert!(output.status.success(), "{program:?} {args:?} failed: {}", String::from_utf8_lossy(&output.stderr));
    parse(&std::fs::read_to_string(&trace_file).unwrap())
}

/// Checks the atomic, durable write of `target` in `calls`: a new temporary file in the same
/// directory gets every byte, is synced, renamed onto `target`, and the directory is synced.
fn check_durable_write(calls: &[Call], target: &Path) -> Result<(), String> {
    let target_text = target.display().to_string();
    let dir_text = target.parent().unwrap().display().to_string();
    let is_rename = |c: &Call| c.name.starts_with("rename") && c.result == 0;
    let Some(rename_at) = calls.iter().position(|c| is_rename(c) && c.strings.last() == Some(&target_text)) else {
        return Err(format!("no rename onto {target_text}: the file is written in place"));
    };
    let temp = calls[rename_at].strings[0].clone();
    if Path::new(&temp).parent() != target.parent() {
        return Err(format!("the temporary file {temp} is not in {dir_text}"));
    }
    let opened = calls[..rename_at].iter().rposition(|c| {
        c.name.starts_with("open") && c.strings.first() == Some(&temp) && c.line.contains("O_CREAT") && c.result >= 0
    });
    let Some(open_at) = opened else { return Err(format!("{temp} is not created before the rename")) };
    if !calls[open_at].line.contains("O_EXCL") {
        return Err(format!("{temp} is not created exclusively (O_EXCL): {}", calls[open_at].line));
    }
    let fd = calls[open_at].result;
    let on_fd = |c: &Call| c.first_int == Some(fd);
    let end = calls[open_at + 1..rename_at]
        .iter()
        .position(|c| c.name == "close" && on_fd(c))
        .map_or(rename_at, |k| open_at + 1 + k);
    let window = &calls[open_at + 1..end];
    let written: i64 = window.iter().filter(|c| c.name.contains("write") && on_fd(c)).map(|c| c.result.max(0)).sum();
    let size = std::fs::metadata(target).map_err(|e| e.to_string())?.len() as i64;
    if written != size {
        return Err(format!("{written} bytes written to {temp}, but {target_text} has {size}"));
    }
    let last_write = window.iter().rposition(|c| c.name.contains("write") && on_fd(c)).unwrap_or(0);
    let synced = window[last_write..].iter().any(|c| (c.name == "fsync" || c.name == "fdatasync") && on_fd(c));
    if !synced {
        return Err(format!("{temp} is not synced (fsync) after its last write and before the rename"));
    }
    let after = &calls[rename_at + 1..];
    let dir_open = after.iter().position(|c| c.name.starts_with("open") && c.strings.first() == Some(&dir_text));
    let Some(dir_open) = dir_open.filter(|&k| after[k].result >= 0) else {
        return Err(format!("the directory {dir_text} is not opened after the rename"));
    };
    let dir_fd = after[dir_open].result;
    if !after[dir_open..].iter().any(|c| c.name == "fsync" && c.first_int == Some(dir_fd)) {
        return Err(format!("the directory {dir_text} is not synced (fsync) after the rename"));
    }
    Ok(())
}

fn meshpaint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_meshpaint"))
}

/// The traced `meshpaint pack` of the Duck to `dir/duck.mpk`.
fn traced_pack(dir: &TempDir) -> (Vec<Call>, PathBuf) {
    let out = dir.join("duck.mpk");
    let calls =
        traced(meshpaint().arg("pack").arg(model("Duck/Duck.glb")).args(["-r", "2", "-o"]).arg(&out), dir.path());
    (calls, out)
}

#[test]
fn a_packed_save_is_synced_renamed_and_its_directory_synced() {
    let dir = TempDir::new("durable-pack");
    let (calls, out) = traced_pack(&dir);
    check_durable_write(&calls, &out).unwrap();
}

#[test]
fn a_gltf_export_is_synced_renamed_and_its_directory_synced() {
    let dir = TempDir::new("durable-export");
    let out = dir.join("duck.glb");
    let calls =
        traced(meshpaint().arg("export").arg(model("Duck/Duck.glb")).args(["-r", "2", "-o"]).arg(&out), dir.path());
    check_durable_write(&calls, &out).unwrap();
}

#[test]
fn an_autosave_recovery_write_is_synced_renamed_and_its_directory_synced() {
    let dir = TempDir::new("durable-recovery");
    let recovery = dir.join(".duck.glb.recovery.mpk");
    let calls = traced(
        meshpaint()
            .arg("autosave-soak")
            .arg(model("Duck/Duck.glb"))
            .arg("--recovery")
            .arg(&recovery)
            .arg("--saved")
            .arg(dir.join("saved.mpk"))
            .args(["-r", "2", "--iterations", "1"]),
        dir.path(),
    );
    check_durable_write(&calls, &recovery).unwrap();
}

#[test]
fn the_check_fails_on_writes_that_are_not_synced() {
    let dir = TempDir::new("durable-negative");
    let source = model("Duck/Duck.glb");
    // In place, never synced.
    let copy = dir.join("copy.glb");
    let calls = traced(Command::new("cp").arg(&source).arg(&copy), dir.path());
    let error = check_durable_write(&calls, &copy).unwrap_err();
    assert!(error.contains("written in place"), "{error}");
    // Renamed, but the data is never synced.
    let moved = dir.join("moved.glb");
    let script = format!(
        "cat '{}' > '{}/.tmp' && mv '{}/.tmp' '{}'",
        source.display(),
        dir.0.display(),
        dir.0.display(),
        moved.display()
    );
    let calls = traced(Command::new("sh").args(["-c", &script]), dir.path());
    let error = check_durable_write(&calls, &moved).unwrap_err();
    assert!(error.contains("not synced") || error.contains("not created"), "{error}");
    // The real trace without the file's fsync, or without the directory's.
    let (calls, out) = traced_pack(&dir);
    let rename_at = calls
        .iter()
        .position(|c| c.name.starts_with("rename") && c.strings.last().is_some_and(|s| s.ends_with("duck.mpk")))
        .unwrap();
    let file_sync = calls[..rename_at].iter().rposition(|c| c.name == "fsync").unwrap();
    let mut without = calls.clone();
    without.remove(file_sync);
    let error = check_durable_write(&without, &out).unwrap_err();
    assert!(error.contains("is not synced (fsync) after its last write"), "{error}");
    let dir_sync = rename_at + 1 + calls[rename_at + 1..].iter().position(|c| c.name == "fsync").unwrap();
    let mut without = calls.clone();
    without.remove(dir_sync);
    let error = check_durable_write(&without, &out).unwrap_err();
    assert!(error.contains("directory") && error.contains("not synced"), "{error}");
}
