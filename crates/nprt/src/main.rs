//! The `nprt` binary: the command line of the library beside it (lib.rs).

// Training allocates and frees large tensors every step; glibc's allocator returns that memory
// to the OS and page-faults it back each time (measured: 8% of a training step).
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    // A closed pipe (`nprt … | head`) ends the process quietly, as for other command-line
    // tools, instead of panicking in println!.
    // SAFETY: restores the default disposition of one signal before any thread starts.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(nprt::main_with(std::env::args_os()));
}
