#!/usr/bin/python3
"""Runs a command as Gradescope's container would: what Docker's default seccomp profile refuses
to a container without CAP_SYS_ADMIN (namespaces, mounts, `clone3`) is refused, after
`tools/gradescope-emulation.sh` has dropped CAP_SYS_ADMIN from the capability bounding set.
Landlock, seccomp, prctl, setuid/setgid and setrlimit stay allowed, as Docker allows them.

Usage: tools/gradescope-emulation.sh COMMAND [ARG...]   (needs Debian's python3-seccomp)
"""
import errno
import os
import sys

import seccomp

# Docker's default profile (moby/profiles/seccomp/default.json): these are allowed only with
# CAP_SYS_ADMIN, which Gradescope's containers do not have.
REFUSED = [
    "unshare", "setns", "mount", "umount2", "pivot_root", "open_tree", "move_mount",
    "fsopen", "fsconfig", "fsmount", "fspick", "mount_setattr", "quotactl", "syslog",
]
# clone's namespace flags: CLONE_NEWNS, NEWCGROUP, NEWUTS, NEWIPC, NEWUSER, NEWPID, NEWNET.
NAMESPACE_FLAGS = [0x00020000, 0x02000000, 0x04000000, 0x08000000, 0x10000000, 0x20000000, 0x40000000]


def main() -> None:
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    docker = seccomp.SyscallFilter(defaction=seccomp.ALLOW)
    for name in REFUSED:
        docker.add_rule(seccomp.ERRNO(errno.EPERM), name)
    for flag in NAMESPACE_FLAGS:
        docker.add_rule(seccomp.ERRNO(errno.EPERM), "clone", seccomp.Arg(0, seccomp.MASKED_EQ, flag, flag))
    # Docker answers clone3 with ENOSYS (its arguments are behind a pointer), so the C library
    # falls back to clone.
    docker.add_rule(seccomp.ERRNO(errno.ENOSYS), "clone3")
    docker.load()
    os.execvp(sys.argv[1], sys.argv[1:])


if __name__ == "__main__":
    main()
