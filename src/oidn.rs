//! Intel Open Image Denoise (OIDN 2), loaded at run time (feature `oidn`).
//!
//! The library is opened with `dlopen` (through `libloading`) rather than linked: a
//! program built with the feature starts, and renders, where the library is missing,
//! and only a request to denoise with it fails, with an [`OidnError`] that names
//! where it looked. The binding is the handful of OIDN 2 C API calls one denoise
//! needs (`oidnNewDevice`, `oidnNewFilter("RT")`, `oidnSetSharedFilterImage`, ...),
//! on the CPU device, with the images shared from host memory.
//!
//! Where the library is looked for ([`Oidn::load`]): with `OIDN_DIR` set, in
//! `$OIDN_DIR/lib` only (the layout of OIDN's release packages, and of the `pyoidn`
//! wheel's `pyoidn/oidn` folder, which `scripts/lib.sh`'s `ensure_oidn` installs);
//! without it, by file name on the system's library path (`LD_LIBRARY_PATH`,
//! `ldconfig`'s cache).
//!
//! ```no_run
//! # use gpu_render::low_level::denoise::{GuidePasses, oidn};
//! # fn run(radiance: &[[f32; 3]], guides: &GuidePasses) -> Result<(), oidn::OidnError> {
//! let library = oidn::Oidn::load()?;
//! let denoised = library.denoise(radiance, guides, &oidn::OidnSettings::default())?;
//! # let _ = denoised;
//! # Ok(())
//! # }
//! ```

use std::ffi::{CStr, c_char, c_int, c_void};
use std::fmt;
use std::path::{Path, PathBuf};

use crate::denoise::GuidePasses;

/// The environment variable naming OIDN's install folder (the library in its `lib/`),
/// as the `oidn` crate reads it.
pub const OIDN_DIR: &str = "OIDN_DIR";

/// The library's file names, most specific first (OIDN 2's ABI is
/// `libOpenImageDenoise.so.2`; the unversioned name is a development symlink).
#[cfg(all(unix, not(target_os = "macos")))]
pub const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];
/// The library's file names, most specific first.
#[cfg(target_os = "macos")]
pub const LIBRARY_NAMES: &[&str] = &["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
/// The library's file names, most specific first.
#[cfg(windows)]
pub const LIBRARY_NAMES: &[&str] = &["OpenImageDenoise.dll"];

/// The folder under `OIDN_DIR` that holds the library (`bin` on Windows, as OIDN's
/// packages lay it out).
#[cfg(not(windows))]
const LIBRARY_FOLDER: &str = "lib";
#[cfg(windows)]
const LIBRARY_FOLDER: &str = "bin";

/// Why denoising with OIDN failed.
#[derive(Debug, thiserror::Error)]
pub enum OidnError {
    /// No candidate file could be opened as the library.
    #[error(
        "Intel Open Image Denoise could not be loaded: {}; {hint}",
        list_attempts(attempts)
    )]
    NotFound {
        /// Each file tried, and why opening it failed.
        attempts: Vec<LoadAttempt>,
        /// What to do about it.
        hint: String,
    },
    /// A library was opened but lacks a function of the OIDN 2 C API (an OIDN 1 or
    /// another library of the same name).
    #[error(
        "{}: not an Open Image Denoise 2 library (no function {symbol}): {source}",
        library.display()
    )]
    MissingFunction {
        /// The file opened.
        library: PathBuf,
        /// The function looked for.
        symbol: &'static str,
        /// The loader's message.
        source: libloading::Error,
    },
    /// OIDN reported an error (its code and message).
    #[error("Open Image Denoise failed while {stage}: {message} (error code {code})")]
    Library {
        /// What was being done.
        stage: &'static str,
        /// OIDN's `OIDNError` code.
        code: i32,
        /// OIDN's message.
        message: String,
    },
    /// The inputs do not describe one image.
    #[error("cannot denoise: {0}")]
    BadInput(String),
}

/// One file [`Oidn::load`] tried to open, and why it failed.
#[derive(Debug)]
pub struct LoadAttempt {
    /// The path or file name passed to the loader.
    pub path: PathBuf,
    /// The loader's message.
    pub error: String,
}

impl fmt::Display for LoadAttempt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.path.display(), self.error)
    }
}

fn list_attempts(attempts: &[LoadAttempt]) -> String {
    attempts
        .iter()
        .map(LoadAttempt::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// How OIDN's `RT` filter is run; the default prefilters nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OidnSettings {
    /// Denoise the albedo and normal passes first, each with its own `RT` filter, and
    /// tell the main filter they are clean (`cleanAux`): OIDN's recipe for noisy
    /// guides (depth of field, motion blur, glossy first hits). Off by default: the
    /// first-hit passes of a pinhole camera are nearly noise-free, and prefiltering
    /// triples the time.
    pub prefilter_guides: bool,
}

// The C API (OpenImageDenoise/oidn.h, version 2).
type Handle = *mut c_void;
type NewDevice = unsafe extern "C" fn(c_int) -> Handle;
type DeviceFn = unsafe extern "C" fn(Handle);
type GetDeviceError = unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int;
type GetDeviceInt = unsafe extern "C" fn(Handle, *const c_char) -> c_int;
type NewFilter = unsafe extern "C" fn(Handle, *const c_char) -> Handle;
type FilterFn = unsafe extern "C" fn(Handle);
type SetFilterBool = unsafe extern "C" fn(Handle, *const c_char, bool);
type SetSharedFilterImage = unsafe extern "C" fn(
    Handle,
    *const c_char,
    *mut c_void,
    c_int,
    usize,
    usize,
    usize,
    usize,
    usize,
);

/// `OIDN_DEVICE_TYPE_CPU`: the images are shared from host memory, which a GPU
/// device may not reach.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;

/// The C API's functions this binding calls, from one loaded library.
struct Api {
    new_device: NewDevice,
    commit_device: DeviceFn,
    release_device: DeviceFn,
    get_device_error: GetDeviceError,
    get_device_int: GetDeviceInt,
    new_filter: NewFilter,
    set_shared_filter_image: SetSharedFilterImage,
    set_filter_bool: SetFilterBool,
    commit_filter: FilterFn,
    execute_filter: FilterFn,
    release_filter: FilterFn,
}

impl Api {
    fn resolve(library: &'static libloading::Library, path: &Path) -> Result<Self, OidnError> {
        fn get<T: Copy>(
            library: &'static libloading::Library,
            path: &Path,
            symbol: &'static str,
        ) -> Result<T, OidnError> {
            let name = format!("{symbol}\0");
            // SAFETY: each `T` below is the function's signature in OIDN 2's oidn.h;
            // the library is never unloaded (leaked), so the pointer stays valid.
            unsafe { library.get::<T>(name.as_bytes()) }
                .map(|s| *s)
                .map_err(|source| OidnError::MissingFunction {
                    library: path.to_path_buf(),
                    symbol,
                    source,
                })
        }
        Ok(Self {
            new_device: get(library, path, "oidnNewDevice")?,
            commit_device: get(library, path, "oidnCommitDevice")?,
            release_device: get(library, path, "oidnReleaseDevice")?,
            get_device_error: get(library, path, "oidnGetDeviceError")?,
            get_device_int: get(library, path, "oidnGetDeviceInt")?,
            new_filter: get(library, path, "oidnNewFilter")?,
            set_shared_filter_image: get(library, path, "oidnSetSharedFilterImage")?,
            set_filter_bool: get(library, path, "oidnSetFilterBool")?,
            commit_filter: get(library, path, "oidnCommitFilter")?,
            execute_filter: get(library, path, "oidnExecuteFilter")?,
            release_filter: get(library, path, "oidnReleaseFilter")?,
        })
    }
}

/// A loaded OIDN library and a committed CPU device of it. Not `Send`: OIDN's
/// device belongs to the thread that made it here.
pub struct Oidn {
    api: Api,
    device: Handle,
    path: PathBuf,
}

impl fmt::Debug for Oidn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Oidn")
            .field("path", &self.path)
            .field("version", &self.version())
            .finish()
    }
}

impl Oidn {
    /// Loads the library from `$OIDN_DIR/lib` where `OIDN_DIR` is set (and only
    /// there), else by file name from the system's library path, and commits a CPU
    /// device.
    pub fn load() -> Result<Self, OidnError> {
        match std::env::var_os(OIDN_DIR) {
            Some(dir) if !dir.is_empty() => Self::load_from_dir(Path::new(&dir)),
            _ => Self::load_candidates(
                LIBRARY_NAMES.iter().map(PathBuf::from).collect(),
                "OIDN_DIR is not set and the system's library path has none; install Open \
                 Image Denoise 2 (scripts/lib.sh's ensure_oidn installs the pyoidn wheel's \
                 copy) and set OIDN_DIR to the folder whose lib/ holds it"
                    .to_owned(),
            ),
        }
    }

    /// Loads the library from `dir`'s `lib` folder (`bin` on Windows): the folder an
    /// OIDN package unpacks to, as `OIDN_DIR` names it.
    pub fn load_from_dir(dir: &Path) -> Result<Self, OidnError> {
        let folder = dir.join(LIBRARY_FOLDER);
        Self::load_candidates(
            LIBRARY_NAMES.iter().map(|name| folder.join(name)).collect(),
            format!(
                "{} must be the folder whose {LIBRARY_FOLDER}/ holds the library (as OIDN_DIR \
                 names it; scripts/lib.sh's ensure_oidn installs the pyoidn wheel's copy)",
                dir.display()
            ),
        )
    }

    fn load_candidates(candidates: Vec<PathBuf>, hint: String) -> Result<Self, OidnError> {
        let mut attempts = Vec::new();
        for path in candidates {
            // SAFETY: loading runs the library's initialisers; OIDN's are sound to
            // run once per process, and a library that is not OIDN fails `resolve`.
            match unsafe { libloading::Library::new(&path) } {
                Ok(library) => {
                    // OIDN's thread pool is not made to be unloaded: the library stays
                    // loaded until the process ends (a second load only counts up).
                    let library: &'static libloading::Library = Box::leak(Box::new(library));
                    let api = Api::resolve(library, &path)?;
                    return Self::with_device(api, path);
                }
                Err(error) => {
                    // dlerror's message starts with the path; say it once.
                    let message = error.to_string();
                    let prefix = format!("{}: ", path.display());
                    let error = message.strip_prefix(&prefix).unwrap_or(&message).to_owned();
                    attempts.push(LoadAttempt { path, error })
                }
            }
        }
        Err(OidnError::NotFound { attempts, hint })
    }

    fn with_device(api: Api, path: PathBuf) -> Result<Self, OidnError> {
        // SAFETY: OIDN 2 C API calls with the handles it returned.
        let device = unsafe { (api.new_device)(DEVICE_TYPE_CPU) };
        if device.is_null() {
            // Errors without a device are kept per thread, read with a null device.
            return Err(
                error_of(&api, std::ptr::null_mut(), "creating its CPU device").unwrap_or_else(
                    || OidnError::Library {
                        stage: "creating its CPU device",
                        code: -1,
                        message: "no device was returned".into(),
                    },
                ),
            );
        }
        let oidn = Self { api, device, path };
        // SAFETY: as above.
        unsafe { (oidn.api.commit_device)(oidn.device) };
        oidn.check("committing its CPU device")?;
        Ok(oidn)
    }

    /// The file the library was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// OIDN's version, as `MAJOR·10000 + MINOR·100 + PATCH` (20501 for 2.5.1).
    pub fn version(&self) -> i32 {
        // SAFETY: a committed device and a NUL-terminated parameter name.
        unsafe { (self.api.get_device_int)(self.device, c"version".as_ptr()) }
    }

    fn check(&self, stage: &'static str) -> Result<(), OidnError> {
        match error_of(&self.api, self.device, stage) {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }

    /// Denoises `radiance` (`guides.width × guides.height` linear HDR RGB pixels,
    /// row-major, top row first) with OIDN's `RT` filter, guided by the first-hit
    /// albedo (in [0, 1]) and world-space normal of `guides` (the depth pass is not
    /// used). Returns the filtered radiance.
    pub fn denoise(
        &self,
        radiance: &[[f32; 3]],
        guides: &GuidePasses,
        settings: &OidnSettings,
    ) -> Result<Vec<[f32; 3]>, OidnError> {
        let (width, height) = (guides.width as usize, guides.height as usize);
        let pixels = width
            .checked_mul(height)
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                OidnError::BadInput(format!("an image of {width}x{height} pixels has none"))
            })?;
        for (name, len) in [
            ("radiance", radiance.len()),
            ("albedo", guides.albedo.len()),
            ("normal", guides.normal.len()),
        ] {
            if len != pixels {
                return Err(OidnError::BadInput(format!(
                    "the {name} pass has {len} pixels, the {width}x{height} image {pixels}"
                )));
            }
        }
        let (albedo, normal) = if settings.prefilter_guides {
            (
                self.run_filter(
                    &[(c"albedo", &guides.albedo)],
                    c"albedo",
                    width,
                    height,
                    &[],
                )?,
                self.run_filter(
                    &[(c"normal", &guides.normal)],
                    c"normal",
                    width,
                    height,
                    &[],
                )?,
            )
        } else {
            (guides.albedo.clone(), guides.normal.clone())
        };
        self.run_filter(
            &[
                (c"color", radiance),
                (c"albedo", &albedo),
                (c"normal", &normal),
            ],
            c"color",
            width,
            height,
            &[(c"hdr", true), (c"cleanAux", settings.prefilter_guides)],
        )
    }

    /// One `RT` filter over `inputs`, all `width × height` FLOAT3 images; the output
    /// has the format of the input named `like`.
    fn run_filter(
        &self,
        inputs: &[(&CStr, &[[f32; 3]])],
        like: &CStr,
        width: usize,
        height: usize,
        flags: &[(&CStr, bool)],
    ) -> Result<Vec<[f32; 3]>, OidnError> {
        let stage = if like == c"color" {
            "filtering the image"
        } else {
            "prefiltering a guide pass"
        };
        let mut output = vec![[0.0f32; 3]; width * height];
        let api = &self.api;
        // SAFETY: OIDN 2 C API calls on a committed device; every image is
        // `width × height` tightly packed FLOAT3 pixels (strides 0 = packed) that
        // outlives the synchronous `oidnExecuteFilter`; OIDN only reads the inputs.
        unsafe {
            let filter = (api.new_filter)(self.device, c"RT".as_ptr());
            if filter.is_null() {
                self.check(stage)?;
                return Err(OidnError::Library {
                    stage,
                    code: -1,
                    message: "no RT filter was returned".into(),
                });
            }
            let release = Release { api, filter };
            for (name, image) in inputs {
                (api.set_shared_filter_image)(
                    filter,
                    name.as_ptr(),
                    image.as_ptr().cast_mut().cast(),
                    FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    0,
                    0,
                );
            }
            (api.set_shared_filter_image)(
                filter,
                c"output".as_ptr(),
                output.as_mut_ptr().cast(),
                FORMAT_FLOAT3,
                width,
                height,
                0,
                0,
                0,
            );
            for (name, value) in flags {
                (api.set_filter_bool)(filter, name.as_ptr(), *value);
            }
            (api.commit_filter)(filter);
            self.check(stage)?;
            (api.execute_filter)(filter);
            self.check(stage)?;
            drop(release);
        }
        Ok(output)
    }
}

/// Releases a filter when dropped (on every path out of `run_filter`).
struct Release<'a> {
    api: &'a Api,
    filter: Handle,
}

impl Drop for Release<'_> {
    fn drop(&mut self) {
        // SAFETY: a filter `oidnNewFilter` returned, released once.
        unsafe { (self.api.release_filter)(self.filter) }
    }
}

impl Drop for Oidn {
    fn drop(&mut self) {
        // SAFETY: the device `oidnNewDevice` returned, released once.
        unsafe { (self.api.release_device)(self.device) }
    }
}

/// The first error OIDN recorded on `device` (a null device: the thread's), cleared.
fn error_of(api: &Api, device: Handle, stage: &'static str) -> Option<OidnError> {
    let mut message: *const c_char = std::ptr::null();
    // SAFETY: `device` is null or a device of this library; the message OIDN returns
    // is NUL-terminated and valid until the next call on the device.
    let code = unsafe { (api.get_device_error)(device, &mut message) };
    if code == 0 {
        return None;
    }
    let message = if message.is_null() {
        String::from("(no message)")
    } else {
        // SAFETY: as above.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    Some(OidnError::Library {
        stage,
        code,
        message,
    })
}

/// Loads OIDN ([`Oidn::load`]) and denoises `radiance` with it ([`Oidn::denoise`]):
/// for one image; keep an [`Oidn`] to denoise many (it loads the library and commits
/// its device once).
pub fn denoise(
    radiance: &[[f32; 3]],
    guides: &GuidePasses,
    settings: &OidnSettings,
) -> Result<Vec<[f32; 3]>, OidnError> {
    Oidn::load()?.denoise(radiance, guides, settings)
}
