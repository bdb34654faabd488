//! tape-core's log messages (the `log` crate: Newton iterations, rejected steps, eigensolver
//! warnings) forwarded to Python's `logging`, under the logger `tapespring.core` and children named
//! after the Rust modules (`tapespring.core.solver.dynamics`, `tapespring.core.eigen`, ...).
//!
//! The records are queued, not sent as they come: a solver thread running without the GIL (or a
//! rayon worker) must never wait for it, since the thread holding it may be waiting for that
//! solver. The queue is emptied into Python, with the GIL, at every progress tick of a run and at
//! its end ([`crate::error::run_detached`]). Which records are queued follows the effective level
//! of the Python logger `tapespring.core`, read at the start of every run ([`sync_level`]), so a
//! run without debug logging formats no debug message.

use std::sync::Mutex;

use log::{Level, LevelFilter, Log, Metadata, Record};
use pyo3::prelude::*;

/// The Python logger of tape-core's messages.
const ROOT: &str = "tapespring.core";

/// Records queued at most between two forwards; beyond, they are counted and dropped (a trace
/// level run without progress ticks must not fill the memory).
const CAPACITY: usize = 100_000;

struct Queue {
    records: Vec<(String, i32, String)>,
    dropped: usize,
}

static QUEUE: Mutex<Queue> = Mutex::new(Queue {
    records: Vec::new(),
    dropped: 0,
});

struct Bridge;

static BRIDGE: Bridge = Bridge;

impl Log for Bridge {
    fn enabled(&self, metadata: &Metadata) -> bool {
        metadata.level() <= log::max_level()
    }

    fn log(&self, record: &Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let mut queue = QUEUE
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if queue.records.len() >= CAPACITY {
            queue.dropped += 1;
            return;
        }
        let entry = (
            logger_name(record.target()),
            python_level(record.level()),
            record.args().to_string(),
        );
        queue.records.push(entry);
    }

    fn flush(&self) {}
}

/// `tape_core::solver::dynamics` -> `tapespring.core.solver.dynamics`.
fn logger_name(target: &str) -> String {
    match target.strip_prefix("tape_core") {
        Some(rest) => format!("{ROOT}{}", rest.replace("::", ".")),
        None => format!("{ROOT}.{}", target.replace("::", ".")),
    }
}

/// The `logging` level number of a `log` level.
fn python_level(level: Level) -> i32 {
    match level {
        Level::Error => 40,
        Level::Warn => 30,
        Level::Info => 20,
        Level::Debug => 10,
        Level::Trace => 5,
    }
}

/// The `log` filter that lets through what a Python logger of effective level `level` shows.
fn filter(level: i64) -> LevelFilter {
    match level {
        i64::MIN..=5 => LevelFilter::Trace,
        6..=10 => LevelFilter::Debug,
        11..=20 => LevelFilter::Info,
        21..=30 => LevelFilter::Warn,
        31..=40 => LevelFilter::Error,
        _ => LevelFilter::Off,
    }
}

/// Installs the bridge as the process's `log` logger (once; a logger installed before by another
/// extension is left in place) and reads the level.
pub fn install(py: Python<'_>) {
    let _ = log::set_logger(&BRIDGE);
    sync_level(py);
}

/// Sets the level of the queued records from the effective level of the Python logger
/// `tapespring.core` (warnings if it cannot be read).
pub fn sync_level(py: Python<'_>) {
    let level = py
        .import("logging")
        .and_then(|l| l.call_method1("getLogger", (ROOT,)))
        .and_then(|l| l.call_method0("getEffectiveLevel"))
        .and_then(|v| v.extract::<i64>())
        .unwrap_or(30);
    log::set_max_level(filter(level));
}

/// Sends the queued records to their Python loggers (a failing handler is Python's business:
/// `logging` reports it itself; an error getting the logger is dropped, not raised into a run).
pub fn forward(py: Python<'_>) {
    let (records, dropped) = {
        let mut queue = QUEUE
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        (std::mem::take(&mut queue.records), std::mem::take(&mut queue.dropped))
    };
    if records.is_empty() && dropped == 0 {
        return;
    }
    let Ok(logging) = py.import("logging") else { return };
    for (name, level, message) in records {
        let _ = logging
            .call_method1("getLogger", (name,))
            .and_then(|l| l.call_method1("log", (level, message)));
    }
    if dropped > 0 {
        let _ = logging.call_method1("getLogger", (ROOT,)).and_then(|l| {
            l.call_method1(
                "log",
                (
                    30,
                    format!("{dropped} log records dropped (more than {CAPACITY} between two progress ticks)"),
                ),
            )
        });
    }
}
