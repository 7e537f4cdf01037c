//! Denoising a render with Intel Open Image Denoise (OIDN 2), the denoiser of Cycles and
//! others: its `RT` filter on the linear HDR image, guided by the renderer's albedo and normal
//! layers.
//!
//! The library is loaded when a denoise is asked for, not linked: a build needs nothing, and a
//! machine without it renders as before and says how to get it when asked to denoise.
//! [`Denoiser::load`] looks, in order, at
//!
//! 1. `OIDN_LIBRARY`, the path of `libOpenImageDenoise.so` (or `.dylib`, `.dll`) itself;
//! 2. the system's loader path (`libOpenImageDenoise.so.2`: a distribution's package, or
//!    `LD_LIBRARY_PATH`);
//! 3. the library inside Python's `pyoidn` package (`pip install pyoidn`, which ships OIDN
//!    2.5), found by asking `python3` where the package is (fixed arguments, no shell).
//!
//! The guides are the renderer's pixel-centre albedo and normal layers: noise-free, so the
//! filter is told so (`cleanAux`) and they are not prefiltered, as OIDN's documentation says of
//! clean auxiliary images. A normal guide needs an albedo guide (OIDN's rule).

use crate::RgbImage;
use glam::Vec3;
use std::ffi::{c_char, c_void, CStr};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a denoise failed.
#[derive(Debug, Error)]
pub enum DenoiseError {
    /// No library was found where [`Denoiser::load`] looks.
    #[error(
        "Intel Open Image Denoise 2 was not found ({tried}); install it with `pip install \
         pyoidn`, or set OIDN_LIBRARY to the path of libOpenImageDenoise.so"
    )]
    NotFound {
        /// Where it looked, and why each failed.
        tried: String,
    },
    /// The library was found but could not be used.
    #[error("cannot use Intel Open Image Denoise at {path}: {reason}")]
    Library {
        /// The library file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A guide's size differs from the image's.
    #[error("the {guide} guide is {got:?}, the image {want:?}")]
    GuideSize {
        /// `albedo` or `normal`.
        guide: &'static str,
        /// The guide's width and height.
        got: (u32, u32),
        /// The image's.
        want: (u32, u32),
    },
    /// OIDN reported an error while filtering.
    #[error("Intel Open Image Denoise failed: {0}")]
    Filter(String),
}

/// The guide layers of a denoise: the albedo and, with it, the normal (both of the image's
/// size; the normal in any consistent space, components in [-1, 1]).
#[derive(Clone, Copy, Debug)]
pub struct Guides<'a> {
    /// Albedo, linear RGB in [0, 1].
    pub albedo: &'a RgbImage,
    /// Shading normals.
    pub normal: Option<&'a RgbImage>,
}

type Device = *mut c_void;
type Filter = *mut c_void;

/// The C functions the denoise calls (OIDN 2's API).
struct Api {
    new_device: unsafe extern "C" fn(i32) -> Device,
    commit_device: unsafe extern "C" fn(Device),
    release_device: unsafe extern "C" fn(Device),
    device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> i32,
    new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    set_shared_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        i32,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    set_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(Filter),
    execute_filter: unsafe extern "C" fn(Filter),
    release_filter: unsafe extern "C" fn(Filter),
}

/// OIDN's `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_CPU: i32 = 1;
/// OIDN's `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: i32 = 3;

/// A loaded Intel Open Image Denoise library.
pub struct Denoiser {
    api: Api,
    path: PathBuf,
    // Kept last: the functions above point into it.
    _library: libloading::Library,
}

impl std::fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Denoiser")
            .field("path", &self.path)
            .finish()
    }
}

/// The library's file name on this platform, for the loader's search.
#[cfg(target_os = "macos")]
const SONAME: &str = "libOpenImageDenoise.2.dylib";
#[cfg(windows)]
const SONAME: &str = "OpenImageDenoise.dll";
#[cfg(not(any(target_os = "macos", windows)))]
const SONAME: &str = "libOpenImageDenoise.so.2";

impl Denoiser {
    /// Loads the library from the first place that has it (see the module documentation).
    pub fn load() -> Result<Self, DenoiseError> {
        let mut tried = Vec::new();
        if let Some(path) = std::env::var_os("OIDN_LIBRARY") {
            // Set but wrong: an error about that file, not a search elsewhere.
            return Self::from_path(Path::new(&path));
        }
        tried.push("OIDN_LIBRARY is not set".to_owned());
        match Self::open(Path::new(SONAME)) {
            Ok(d) => return Ok(d),
            Err(e) => tried.push(format!("{SONAME}: {e}")),
        }
        match pyoidn_library() {
            Ok(path) => return Self::from_path(&path),
            Err(e) => tried.push(format!("pyoidn: {e}")),
        }
        Err(DenoiseError::NotFound {
            tried: tried.join("; "),
        })
    }

    /// Loads the library at `path`.
    pub fn from_path(path: &Path) -> Result<Self, DenoiseError> {
        Self::open(path).map_err(|reason| DenoiseError::Library {
            path: path.to_owned(),
            reason,
        })
    }

    /// Opens `path` (a file, or a name for the loader's search) and finds the functions.
    fn open(path: &Path) -> Result<Self, String> {
        // SAFETY: loading a library runs its initialisers; OIDN's only set up its own state.
        let library = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the symbol is OIDN 2's function of that name, whose C signature the
                // field's type declares (oidn.h).
                *unsafe { library.get(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| format!("{}: {e}", $name))?
            };
        }
        let api = Api {
            new_device: sym!("oidnNewDevice"),
            commit_device: sym!("oidnCommitDevice"),
            release_device: sym!("oidnReleaseDevice"),
            device_error: sym!("oidnGetDeviceError"),
            new_filter: sym!("oidnNewFilter"),
            set_shared_image: sym!("oidnSetSharedFilterImage"),
            set_bool: sym!("oidnSetFilterBool"),
            commit_filter: sym!("oidnCommitFilter"),
            execute_filter: sym!("oidnExecuteFilter"),
            release_filter: sym!("oidnReleaseFilter"),
        };
        Ok(Self {
            api,
            path: path.to_owned(),
            _library: library,
        })
    }

    /// Where the library was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// `image` denoised by the `RT` filter (HDR, high quality), with `guides` if given.
    pub fn denoise(
        &self,
        image: &RgbImage,
        guides: Option<Guides<'_>>,
    ) -> Result<RgbImage, DenoiseError> {
        let size = (image.width, image.height);
        if let Some(g) = guides {
            for (guide, layer) in [("albedo", Some(g.albedo)), ("normal", g.normal)] {
                if let Some(l) = layer {
                    if (l.width, l.height) != size {
                        return Err(DenoiseError::GuideSize {
                            guide,
                            got: (l.width, l.height),
                            want: size,
                        });
                    }
                }
            }
        }
        let mut out = RgbImage::new(image.width, image.height);
        if image.pixels.is_empty() {
            return Ok(out);
        }
        // OIDN reads the inputs through mutable pointers; give it copies it may touch.
        let mut color = image.pixels.clone();
        let mut albedo = guides.map(|g| g.albedo.pixels.clone());
        let mut normal = guides.and_then(|g| g.normal).map(|n| n.pixels.clone());
        let api = &self.api;
        // SAFETY: the device and filter are used on this thread only and released below; the
        // shared images point at buffers of width x height packed f32 triples (glam's Vec3 is
        // repr(C)) that outlive the filter's execution.
        unsafe {
            let device = (api.new_device)(DEVICE_CPU);
            if device.is_null() {
                return Err(DenoiseError::Filter("no CPU device".into()));
            }
            (api.commit_device)(device);
            let result = (|| {
                check(api, device)?;
                let filter = (api.new_filter)(device, c"RT".as_ptr());
                if filter.is_null() {
                    check(api, device)?;
                    return Err(DenoiseError::Filter("no RT filter".into()));
                }
                let (w, h) = (image.width as usize, image.height as usize);
                let stride = std::mem::size_of::<Vec3>();
                let set = |name: &CStr, buffer: &mut [Vec3]| {
                    (api.set_shared_image)(
                        filter,
                        name.as_ptr(),
                        buffer.as_mut_ptr().cast(),
                        FORMAT_FLOAT3,
                        w,
                        h,
                        0,
                        stride,
                        stride * w,
                    );
                };
                set(c"color", &mut color);
                if let Some(a) = albedo.as_mut() {
                    set(c"albedo", a);
                    if let Some(n) = normal.as_mut() {
                        set(c"normal", n);
                    }
                    (api.set_bool)(filter, c"cleanAux".as_ptr(), true);
                }
                set(c"output", &mut out.pixels);
                (api.set_bool)(filter, c"hdr".as_ptr(), true);
                (api.commit_filter)(filter);
                let committed = check(api, device);
                if committed.is_ok() {
                    (api.execute_filter)(filter);
                }
                (api.release_filter)(filter);
                committed?;
                check(api, device)
            })();
            (api.release_device)(device);
            result?;
        }
        Ok(out)
    }
}

/// The device's pending error, if any.
///
/// # Safety
/// `device` is a live device of `api`'s library.
unsafe fn check(api: &Api, device: Device) -> Result<(), DenoiseError> {
    let mut message: *const c_char = std::ptr::null();
    // SAFETY: as the caller promises; OIDN returns a static or device-owned string.
    let code = unsafe { (api.device_error)(device, &mut message) };
    if code == 0 {
        return Ok(());
    }
    let text = if message.is_null() {
        format!("error {code}")
    } else {
        // SAFETY: a NUL-terminated string that lives until the next call on the device.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    Err(DenoiseError::Filter(text))
}

/// The OIDN library inside Python's `pyoidn` package: `python3` is asked where the package is
/// (its arguments are fixed; nothing reaches a shell), and its `oidn/lib` folder is searched.
fn pyoidn_library() -> Result<PathBuf, String> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import importlib.util as u; s = u.find_spec('pyoidn'); \
             print(s.submodule_search_locations[0] if s else '')",
        ])
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("cannot run python3: {e}"))?;
    let dir = String::from_utf8_lossy(&out.stdout).trim().to_owned();
    if dir.is_empty() {
        return Err("python3 has no pyoidn package".into());
    }
    let lib = Path::new(&dir).join("oidn").join("lib");
    let names: &[&str] = &[
        "libOpenImageDenoise.so.2",
        "libOpenImageDenoise.so",
        "libOpenImageDenoise.2.dylib",
        "OpenImageDenoise.dll",
    ];
    names
        .iter()
        .map(|n| lib.join(n))
        .find(|p| p.is_file())
        .ok_or_else(|| format!("no libOpenImageDenoise in {}", lib.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noisy flat image denoises towards its mean, when the library is there (the CI
    /// installs it and requires it); without it, the error says how to get it.
    #[test]
    fn denoising_a_noisy_flat_image_removes_the_noise() {
        let d = match Denoiser::load() {
            Ok(d) => d,
            Err(e) => {
                let text = e.to_string();
                assert!(text.contains("pip install pyoidn"), "{text}");
                // CI installs the library and sets this: there the test may not skip.
                assert!(std::env::var_os("STREAKS_REQUIRE_OIDN").is_none(), "{text}");
                eprintln!("skipped: {text}");
                return;
            }
        };
        let (w, h) = (64u32, 48u32);
        let mut noisy = RgbImage::new(w, h);
        let mut state = 12345u32;
        for p in &mut noisy.pixels {
            // A value of 0.5 on average: 0 or 1 by a hash, a Monte Carlo estimate at 1 spp.
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            *p = Vec3::splat(if state & 1 == 0 { 0.0 } else { 1.0 });
        }
        let albedo = RgbImage {
            width: w,
            height: h,
            pixels: vec![Vec3::splat(0.8); (w * h) as usize],
        };
        let normal = RgbImage {
            width: w,
            height: h,
            pixels: vec![Vec3::Z; (w * h) as usize],
        };
        let guides = Guides {
            albedo: &albedo,
            normal: Some(&normal),
        };
        for g in [None, Some(guides)] {
            let out = d.denoise(&noisy, g).expect("denoised");
            assert_eq!((out.width, out.height), (w, h));
            let rms = |img: &RgbImage| {
                (img.pixels.iter().map(|p| (p.x - 0.5).powi(2)).sum::<f32>()
                    / img.pixels.len() as f32)
                    .sqrt()
            };
            assert!(rms(&noisy) > 0.45);
            assert!(rms(&out) < 0.15, "rms {} after", rms(&out));
        }
        let small = RgbImage::new(2, 2);
        let err = d
            .denoise(
                &noisy,
                Some(Guides {
                    albedo: &small,
                    normal: None,
                }),
            )
            .unwrap_err();
        assert!(err.to_string().contains("albedo"), "{err}");
    }

    #[test]
    fn a_wrong_library_path_is_named() {
        let err = Denoiser::from_path(Path::new("/nonexistent/libOpenImageDenoise.so"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/libOpenImageDenoise.so"), "{err}");
    }
}
