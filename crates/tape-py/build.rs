//! Stamps the native module with the source it was built from, so that every saved result and
//! every command's output names the code that computed it: the package version alone (0.1.0 for
//! every commit so far) does not.
//!
//! Sets `TAPESPRING_BUILD_LOCAL`, the local part of a PEP 440 version (`g<commit>`, `.dirty` if
//! tracked files differed from that commit when this ran, `.debug` for an unoptimised build), or
//! an empty string when git or the repository is not at hand (a source archive).

use std::path::PathBuf;
use std::process::Command;

/// Hex digits of the commit kept, as `git describe` does by default and more (10: no clash in a
/// repository of this size).
const COMMIT_DIGITS: usize = 10;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let mut parts = Vec::new();
    if let Some(commit) = git(&["rev-parse", "HEAD"]).filter(|c| c.len() >= COMMIT_DIGITS) {
        parts.push(format!("g{}", &commit[..COMMIT_DIGITS]));
        let dirty = git(&["status", "--porcelain", "--untracked-files=no"]);
        if dirty.is_some_and(|d| !d.is_empty()) {
            parts.push("dirty".to_string());
        }
        // A commit, a checkout or an amend appends to HEAD's log: stamp again then, and when
        // the sources compiled here change. Python files are not compiled, so "dirty" says
        // what the Rust sources were at build time (the docs of `build_version` say so).
        if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
            let log = PathBuf::from(dir).join("logs").join("HEAD");
            println!("cargo:rerun-if-changed={}", log.display());
        }
    }
    if std::env::var("PROFILE").as_deref() != Ok("release") {
        parts.push("debug".to_string());
    }
    println!("cargo:rustc-env=TAPESPRING_BUILD_LOCAL={}", parts.join("."));
    for path in [
        "build.rs",
        "Cargo.toml",
        "src",
        "../tape-core/Cargo.toml",
        "../tape-core/src",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
}
