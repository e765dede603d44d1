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
    use std::sync::atomic::{AtomicPtr, AtomicUsize, Ordering};
    use std::sync::Once;

    /// The message the handler writes, made beforehand: a signal handler may only call
    /// async-signal-safe functions (write, _exit), not format or allocate.
    static MESSAGE: AtomicPtr<u8> = AtomicPtr::new(std::ptr::null_mut());
    static LENGTH: AtomicUsize = AtomicUsize::new(0);
    static INSTALL: Once = Once::new();

    pub(super) fn name(path: &Path) {
        let text = format!(
            "\nerror: '{}' changed while this process had it mapped (SIGBUS: it was truncated or \
             replaced in place by another program); nothing read from it since can be trusted. \
             Leave dataset files alone while a command reads them, then run the command again\n",
            path.display()
        );
        // Leaked on purpose: the handler may read it at any moment for the rest of the process.
        let bytes: &'static mut [u8] = Box::leak(text.into_bytes().into_boxed_slice());
        LENGTH.store(0, Ordering::SeqCst);
        MESSAGE.store(bytes.as_mut_ptr(), Ordering::SeqCst);
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
        let (text, len) = (
            MESSAGE.load(Ordering::SeqCst),
            LENGTH.load(Ordering::SeqCst),
        );
        // SAFETY: write(2) and _exit(2) are async-signal-safe; `text` holds `len` bytes that
        // are never freed.
        unsafe {
            if !text.is_null() && len > 0 {
                libc::write(2, text.cast(), len);
            }
            libc::_exit(1);
        }
    }
}
