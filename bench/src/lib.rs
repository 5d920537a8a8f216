//! Ray-tracing benchmarks: the test mesh, the fixed ray workloads, and timing them.
//!
//! Everything here runs the student-facing code path ([`raylab::geometry::Bvh::traverse`], with
//! the checkpoint 2 and 3 tests inside): a benchmark measures what the grader's renders run. The
//! `raybench` binary and `cargo bench` are built on this module; docs/PERFORMANCE.md has the
//! figures and the commands behind them.

mod icosphere;
mod memory;
mod trace;
mod workload;

#[cfg(feature = "peer-embree")]
pub mod embree;

pub use icosphere::{bumpy_icosphere, grid_size_for, write_obj};
pub use memory::peak_memory_bytes;
pub use trace::{trace, TraceReport, Tracer};
pub use workload::Workload;
