//! The resource wall: what a graded child may use beyond its wall-clock time. The kernel holds
//! the first two even for root (`setrlimit` in the child before it runs); the grader watches the
//! third ([`crate::run::child::written`]).

/// Resource limits for a child, beyond its wall-clock time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Address space, in bytes (`RLIMIT_AS`); an allocation beyond it fails.
    pub memory: u64,
    /// Largest file the child may write, in bytes (`RLIMIT_FSIZE`).
    pub file_size: u64,
    /// What it may add to the folders it may write, over all files (watched by [`crate::run::child::written`]).
    pub written: Budget,
}

impl Limits {
    /// For graded code (renders, unit tests): 4 GiB of address space (a correct render needs a
    /// few hundred MiB, thread stacks and allocator arenas included), files of at most 64 MiB,
    /// 256 MiB and 1,000 entries in all (a render writes one image of at most a few MiB; the
    /// checkpoint tests write none).
    pub const GRADED: Option<Limits> = Some(Limits {
        memory: 4 << 30,
        file_size: 64 << 20,
        written: Budget { bytes: 256 << 20, entries: 1_000 },
    });

    /// For each process of a build (cargo, rustc, the linker): 4 GiB of address space (rustc
    /// needs under 1 GiB for the renderer; a 128 MiB `static` took 2.8 GB), files of at most 1 GiB
    /// (the largest the renderer's build writes is under 200 MB), 8 GiB and 50,000 entries in all
    /// (a cold build of the whole workspace, grader and benchmarks included, writes 1.1 GB in
    /// 4,630 entries).
    pub const BUILD: Option<Limits> = Some(Limits {
        memory: 4 << 30,
        file_size: 1 << 30,
        written: Budget { bytes: 8 << 30, entries: 50_000 },
    });
}

/// What a child may add to its writable folders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Bytes of disk, counted as the blocks each file holds (a sparse file costs what it stores).
    pub bytes: u64,
    /// Files, folders and links: each costs an inode, which can run out before the bytes do.
    pub entries: u64,
}
