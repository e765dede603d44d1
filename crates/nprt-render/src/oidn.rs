//! Intel Open Image Denoise, loaded at run time from the shared library that the `oidn` PyPI
//! wheel ships (OIDN 1.4.3; `scripts/oidn.sh` unpacks it into target/oidn/lib). Optional: when
//! the library is absent, the denoised baselines are reported as unavailable, with why, and
//! traced direct light cannot be denoised.

use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use anyhow::{bail, Context, Result};
use glam::Vec3;
use libloading::{Library, Symbol};
use nprt_trace::GBuffer;

const LIB: &str = "libOpenImageDenoise.so.1.4.3";
const TBB: &str = "libtbb.so.12.5";
/// OIDN_FORMAT_FLOAT3.
const FLOAT3: i32 = 3;

/// The OIDN library, opened.
pub struct Oidn {
    lib: Library,
    _tbb: Library,
}

/// Where the library is looked for: $NPRT_OIDN_DIR, then target/oidn/lib beside the running
/// executable's build folder.
pub fn search_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("NPRT_OIDN_DIR") {
        dirs.push(PathBuf::from(d));
    }
    if let Ok(exe) = std::env::current_exe() {
        for anc in exe.ancestors().skip(1).take(3) {
            dirs.push(anc.join("oidn/lib"));
        }
    }
    dirs
}

type NewDevice = unsafe extern "C" fn(i32) -> *mut c_void;
type Handle = unsafe extern "C" fn(*mut c_void);
type NewFilter = unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void;
type SetImage = unsafe extern "C" fn(
    *mut c_void,
    *const c_char,
    *mut c_void,
    i32,
    usize,
    usize,
    usize,
    usize,
    usize,
);
type SetBool = unsafe extern "C" fn(*mut c_void, *const c_char, bool);
type GetError = unsafe extern "C" fn(*mut c_void, *mut *const c_char) -> i32;

impl Oidn {
    /// Opens the library (once per process; it stays loaded, as TBB's worker threads outlive
    /// any one call and unloading under them crashes at exit).
    pub fn open() -> Result<&'static Oidn> {
        static OIDN: OnceLock<std::result::Result<Oidn, String>> = OnceLock::new();
        OIDN.get_or_init(|| Self::find().map_err(|e| format!("{e:#}")))
            .as_ref()
            .map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// Opens the library from the first search folder that holds it.
    fn find() -> Result<Self> {
        let dirs = search_dirs();
        let dir = dirs.iter().find(|d| d.join(LIB).is_file()).with_context(|| {
            format!(
                "Open Image Denoise not found ({LIB} in none of {}); run scripts/oidn.sh to install it",
                dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>().join(", ")
            )
        })?;
        Self::open_in(dir)
    }

    fn open_in(dir: &Path) -> Result<Self> {
        // SAFETY: these are OIDN's own libraries; loading runs only their initialisers. TBB
        // first, so that OIDN's dependency on it resolves to this copy.
        let tbb = unsafe { Library::new(dir.join(TBB)) }
            .with_context(|| format!("cannot load {}", dir.join(TBB).display()))?;
        let lib = unsafe { Library::new(dir.join(LIB)) }
            .with_context(|| format!("cannot load {}", dir.join(LIB).display()))?;
        Ok(Oidn { lib, _tbb: tbb })
    }

    /// Denoises an HDR frame with its G-buffer as auxiliaries: albedo kd + ks (clamped to 1)
    /// and the shading normal, both zero on background pixels.
    pub fn denoise_frame(
        &self,
        color: &[Vec3],
        g: &GBuffer,
        width: usize,
        height: usize,
    ) -> Result<Vec<Vec3>> {
        let albedo: Vec<Vec3> =
            g.kd.iter()
                .zip(&g.ks)
                .map(|(kd, ks)| (*kd + *ks).min(Vec3::ONE))
                .collect();
        self.denoise(color, &albedo, &g.normal, width, height)
    }

    /// Denoises HDR `color` with `albedo` and `normal` auxiliary images (the "RT" filter).
    pub fn denoise(
        &self,
        color: &[Vec3],
        albedo: &[Vec3],
        normal: &[Vec3],
        width: usize,
        height: usize,
    ) -> Result<Vec<Vec3>> {
        let n = width * height;
        if color.len() != n || albedo.len() != n || normal.len() != n {
            bail!("denoiser inputs of mismatched sizes");
        }
        let mut output = vec![Vec3::ZERO; n];
        // SAFETY: the signatures are OIDN 1.4's C API; images are tightly packed float3 buffers
        // that outlive the filter's execution, and both handles are released before returning.
        unsafe {
            // libloading's typed `get` checks nothing about the signature either; the types
            // above are the contract.
            let lib = &self.lib;
            let new_device: NewDevice = symbol(lib, "oidnNewDevice")?;
            let commit_device: Handle = symbol(lib, "oidnCommitDevice")?;
            let release_device: Handle = symbol(lib, "oidnReleaseDevice")?;
            let get_error: GetError = symbol(lib, "oidnGetDeviceError")?;
            let new_filter: NewFilter = symbol(lib, "oidnNewFilter")?;
            let set_image: SetImage = symbol(lib, "oidnSetSharedFilterImage")?;
            let set_bool: SetBool = symbol(lib, "oidnSetFilter1b")?;
            let commit_filter: Handle = symbol(lib, "oidnCommitFilter")?;
            let execute: Handle = symbol(lib, "oidnExecuteFilter")?;
            let release_filter: Handle = symbol(lib, "oidnReleaseFilter")?;

            let device = new_device(0);
            if device.is_null() {
                bail!("OIDN could not create a device");
            }
            commit_device(device);
            let filter = new_filter(device, c"RT".as_ptr());
            let images: [(&str, *mut c_void); 4] = [
                ("color", color.as_ptr() as *mut c_void),
                ("albedo", albedo.as_ptr() as *mut c_void),
                ("normal", normal.as_ptr() as *mut c_void),
                ("output", output.as_mut_ptr() as *mut c_void),
            ];
            for (name, ptr) in images {
                let name = CString::new(name).expect("no NUL");
                set_image(
                    filter,
                    name.as_ptr(),
                    ptr,
                    FLOAT3,
                    width,
                    height,
                    0,
                    12,
                    12 * width,
                );
            }
            set_bool(filter, c"hdr".as_ptr(), true);
            commit_filter(filter);
            execute(filter);
            let mut msg: *const c_char = std::ptr::null();
            let code = get_error(device, &mut msg);
            release_filter(filter);
            release_device(device);
            if code != 0 {
                let text = if msg.is_null() {
                    String::new()
                } else {
                    CStr::from_ptr(msg).to_string_lossy().into_owned()
                };
                bail!("OIDN failed (error {code}): {text}");
            }
        }
        Ok(output)
    }
}

/// The function `name` of `lib` as the function-pointer type `F`.
///
/// # Safety
/// `F` must be the symbol's true C signature.
unsafe fn symbol<F: Copy>(lib: &Library, name: &str) -> Result<F> {
    let s: Symbol<F> =
        unsafe { lib.get(name.as_bytes()) }.with_context(|| format!("OIDN lacks {name}"))?;
    Ok(*s)
}
