//! How libtorch runs in this process: settings a program that trains or plans applies once at
//! its start, before any other thread exists (the `seads` binary does, for the commands that
//! run libtorch in parallel). Neither changes a number; both change how long runs take.

/// Keeps freed memory in the process: libtorch allocates and frees multi-megabyte temporaries
/// on every training step, and glibc's defaults return them to the OS (mmap / trim), so each
/// step paid page faults that cost ~15 % of training time. Same effect as
/// `GLIBC_TUNABLES=glibc.malloc.mmap_threshold=…:glibc.malloc.trim_threshold=…`.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[allow(unsafe_code)]
    // SAFETY: mallopt only changes allocator parameters; it is called once, before any other
    // thread exists, with valid parameter constants and non-negative values.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 30);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
    }
}

/// The variable that bounds how long libtorch's OpenMP threads (libgomp) spin before they sleep.
const SPIN: &str = "GOMP_SPINCOUNT";

/// Makes libgomp's idle threads spin 1000 iterations before they sleep instead of its default
/// 300000, by running this program again with `GOMP_SPINCOUNT=1000` (libgomp reads it when it is
/// loaded, before `main`). On a machine whose cores are busy with other work (a second run, the
/// other worker of a sweep), a thread spinning at a barrier holds the core that the thread it
/// waits for needs. A 10⁴-step LightsOutCursor run with two SAC threads beside two or three busy
/// single-threaded processes did not reach step 4473 in 150 s with the default, and finished in
/// 33–50 s at 1000 (3000: 58 s, 10000: 60–84 s); alone on the machine it takes 5 % longer at
/// 1000 (15.4 → 16.2 s, docs/results/log-2026-11.md). The same numbers either way: only waiting changes. A
/// user's own `GOMP_SPINCOUNT` or `OMP_WAIT_POLICY` is kept. If the program cannot be run again,
/// it goes on as it is.
pub fn spin_briefly_in_libgomp() {
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        if std::env::var_os(SPIN).is_some() || std::env::var_os("OMP_WAIT_POLICY").is_some() {
            return;
        }
        let Ok(exe) = std::env::current_exe() else {
            return;
        };
        let mut args = std::env::args_os();
        let arg0 = args.next().unwrap_or_else(|| exe.clone().into_os_string());
        // Returns only on failure; the process then runs with libgomp's defaults.
        let _ = std::process::Command::new(exe)
            .arg0(arg0)
            .args(args)
            .env(SPIN, "1000")
            .exec();
    }
}
