//! The seccomp filter of a graded process: every system call is allowed but those below, which
//! fail with `EPERM` (`clone3` with `ENOSYS`, so the C library starts threads with `clone`).
//!
//! | refused | unless | stops |
//! |---|---|---|
//! | `execve` | never | running another program, or this one again without the switch |
//! | `execveat` | descriptor `fd` with `AT_EMPTY_PATH` (the launcher's own exec) | the same |
//! | `fork`, `vfork`, `clone` | `clone` with `CLONE_THREAD` (a thread) | a second process |
//! | `socket`, `socketpair` | `AF_UNIX` | the network |
//! | `kill`, `tgkill`, `rt_(tg)sigqueueinfo` | the target is this process (or `kill(0)`) | signals to the grader |
//! | `tkill`, `ptrace`, `process_vm_*`, `pidfd_*`, `kcmp` | never | reaching other processes |
//! | `setsid`, `setpgid` | never | leaving the process group the grader kills |
//! | `setrlimit`, `prlimit64` | `prlimit64` that only reads | raising a limit |
//! | `unshare`, `setns`, `mount`..., `chroot`, `*_by_handle_at` | never | leaving the file wall |
//! | `io_uring_*`, `bpf`, `perf_event_open`, `userfaultfd`, key calls | never | calls this filter cannot see into |

use std::collections::BTreeMap;

use super::wall_error::WallError;
use super::Profile;
use seccompiler::{
    BackendError, BpfProgram, SeccompAction, SeccompCmpArgLen as Len, SeccompCmpOp as Op, SeccompCondition,
    SeccompFilter, SeccompRule, TargetArch,
};

/// Installs the filter of `profile` on the calling thread (the launcher has one), letting
/// `execveat` through for descriptor `fd` only in a run. A build may run programs and start
/// processes (cargo runs rustc, rustc the linker): its filter keeps only the network, other
/// processes' memory and the kernel's side doors closed.
pub fn install(fd: libc::c_int, profile: Profile) -> Result<(), WallError> {
    let pid = std::process::id() as u64;
    let arch = TargetArch::try_from(std::env::consts::ARCH)?;
    let rules = match profile {
        Profile::Run => refusals(fd, pid),
        Profile::Build => build_refusals(),
    };
    let mut programs = vec![compile(rules?, libc::EPERM, arch)?];
    if profile == Profile::Run {
        let clone3 = BTreeMap::from([(libc::SYS_clone3, Vec::new())]);
        programs.insert(0, compile(clone3, libc::ENOSYS, arch)?);
    }
    for program in &programs {
        seccompiler::apply_filter(program)?;
    }
    Ok(())
}

fn compile(
    rules: BTreeMap<i64, Vec<SeccompRule>>,
    errno: i32,
    arch: TargetArch,
) -> Result<BpfProgram, BackendError> {
    let filter = SeccompFilter::new(rules, SeccompAction::Allow, SeccompAction::Errno(errno as u32), arch)?;
    filter.try_into()
}

/// A rule that holds when every `(argument, length, operator, value)` does.
fn when(conditions: &[(u8, Len, Op, u64)]) -> Result<SeccompRule, BackendError> {
    let conditions = conditions
        .iter()
        .map(|(arg, len, op, value)| SeccompCondition::new(*arg, len.clone(), op.clone(), *value))
        .collect::<Result<Vec<_>, _>>()?;
    SeccompRule::new(conditions)
}

/// The calls every profile refuses: other processes' memory and descriptors, the file wall's
/// side doors, and calls this filter cannot see into.
const ALWAYS: [i64; 29] = [
    libc::SYS_ptrace,
    libc::SYS_process_vm_readv,
    libc::SYS_process_vm_writev,
    libc::SYS_pidfd_getfd,
    libc::SYS_kcmp,
    libc::SYS_unshare,
    libc::SYS_setns,
    libc::SYS_mount,
    libc::SYS_umount2,
    libc::SYS_pivot_root,
    libc::SYS_chroot,
    libc::SYS_open_tree,
    libc::SYS_move_mount,
    libc::SYS_fsopen,
    libc::SYS_fsconfig,
    libc::SYS_fsmount,
    libc::SYS_fspick,
    libc::SYS_mount_setattr,
    libc::SYS_name_to_handle_at,
    libc::SYS_open_by_handle_at,
    libc::SYS_io_uring_setup,
    libc::SYS_io_uring_enter,
    libc::SYS_io_uring_register,
    libc::SYS_bpf,
    libc::SYS_perf_event_open,
    libc::SYS_userfaultfd,
    libc::SYS_keyctl,
    libc::SYS_add_key,
    libc::SYS_request_key,
];

/// A build's refusals: [`ALWAYS`], and every socket but a UNIX one.
fn build_refusals() -> Result<BTreeMap<i64, Vec<SeccompRule>>, BackendError> {
    let not_unix = || when(&[(0, Len::Dword, Op::Ne, libc::AF_UNIX as u64)]).map(|r| vec![r]);
    let mut rules = BTreeMap::from([(libc::SYS_socket, not_unix()?), (libc::SYS_socketpair, not_unix()?)]);
    rules.extend(ALWAYS.map(|call| (call, Vec::new())));
    Ok(rules)
}

/// A run's refusals: an empty rule list refuses the call always, otherwise when any rule holds.
fn refusals(fd: libc::c_int, pid: u64) -> Result<BTreeMap<i64, Vec<SeccompRule>>, BackendError> {
    let not_unix = || when(&[(0, Len::Dword, Op::Ne, libc::AF_UNIX as u64)]).map(|r| vec![r]);
    let not_self = || when(&[(0, Len::Dword, Op::Ne, pid)]).map(|r| vec![r]);
    let mut rules = BTreeMap::from([
        (libc::SYS_execve, Vec::new()),
        (
            libc::SYS_execveat,
            vec![
                when(&[(0, Len::Dword, Op::Ne, fd as u64)])?,
                when(&[(4, Len::Dword, Op::Ne, libc::AT_EMPTY_PATH as u64)])?,
            ],
        ),
        (libc::SYS_clone, vec![when(&[(0, Len::Qword, Op::MaskedEq(libc::CLONE_THREAD as u64), 0)])?]),
        (libc::SYS_socket, not_unix()?),
        (libc::SYS_socketpair, not_unix()?),
        (libc::SYS_kill, vec![when(&[(0, Len::Dword, Op::Ne, pid), (0, Len::Dword, Op::Ne, 0)])?]),
        (libc::SYS_tgkill, not_self()?),
        (libc::SYS_rt_sigqueueinfo, not_self()?),
        (libc::SYS_rt_tgsigqueueinfo, not_self()?),
        (libc::SYS_prlimit64, vec![when(&[(2, Len::Qword, Op::Ne, 0)])?]),
    ]);
    let always = [
        libc::SYS_tkill,
        libc::SYS_pidfd_open,
        libc::SYS_pidfd_send_signal,
        libc::SYS_setsid,
        libc::SYS_setpgid,
    ];
    rules.extend(ALWAYS.map(|call| (call, Vec::new())));
    rules.extend(always.map(|call| (call, Vec::new())));
    // Calls only x86_64 has (aarch64 forks with `clone` and limits with `prlimit64`).
    #[cfg(target_arch = "x86_64")]
    rules.extend([libc::SYS_fork, libc::SYS_vfork, libc::SYS_setrlimit].map(|call| (call, Vec::new())));
    Ok(rules)
}
