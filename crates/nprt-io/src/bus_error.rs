//! A file mapped into memory that another process truncates makes this one's next read of a
//! lost page raise SIGBUS, which ends the process with no word of why (a pack cut short while
//! `nprt train` read it: exit status 135). A command that maps a file names it here; the
//! handler then says which file it was and exits with status 1.

use std::path::Path;

/// Names `path` as the file to blame if the process gets SIGBUS (the last named, where there
/// are several), installing the handler on first use. A no-op where there are no signals.
pub fn name_on_bus_error(path: &Path) {
    #[cfg(unix)]
    unix::name(path);
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(unix)]
mod unix {
    use std::path::Path;
    use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering};
    use std::sync::Once;

    /// Room for the message: a longer one is cut short.
    const ROOM: usize = 1024;

    /// The message the handler writes, made beforehand in a fixed buffer: a signal handler may
    /// only call async-signal-safe functions (write, _exit), not format or allocate, and a
    /// buffer per named file would never be freed.
    static MESSAGE: [AtomicU8; ROOM] = [const { AtomicU8::new(0) }; ROOM];
    static LENGTH: AtomicUsize = AtomicUsize::new(0);
    static INSTALL: Once = Once::new();

    pub(super) fn name(path: &Path) {
        let text = format!(
            "\nerror: '{}' changed while this process had it mapped (SIGBUS: it was truncated or \
             replaced in place by another program); nothing read from it since can be trusted. \
             Leave dataset files alone while a command reads them, then run the command again\n",
            path.display()
        );
        let bytes = &text.as_bytes()[..text.len().min(ROOM)];
        LENGTH.store(0, Ordering::SeqCst);
        for (slot, &b) in MESSAGE.iter().zip(bytes) {
            slot.store(b, Ordering::Relaxed);
        }
        LENGTH.store(bytes.len(), Ordering::SeqCst);
        INSTALL.call_once(|| {
            // SAFETY: a plain handler for SIGBUS, which only calls write(2) and _exit(2).
            unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_bus_error as extern "C" fn(libc::c_int) as usize;
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(libc::SIGBUS, &action, std::ptr::null_mut());
            }
        });
    }

    extern "C" fn on_bus_error(_: libc::c_int) {
        let len = LENGTH.load(Ordering::SeqCst).min(ROOM);
        let mut text = [0u8; ROOM];
        for (b, slot) in text.iter_mut().zip(&MESSAGE).take(len) {
            *b = slot.load(Ordering::Relaxed);
        }
        // SAFETY: write(2) and _exit(2) are async-signal-safe; `text` holds `len` bytes.
        unsafe {
            if len > 0 {
                libc::write(2, text.as_ptr().cast(), len);
            }
            libc::_exit(1);
        }
    }
}
