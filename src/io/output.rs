//! Buffers to files: PNG pictures for eyes, one EXR file with the raw floats.
//!
//! Every file is written under a temporary name and then renamed ([`Pending`]), so
//! a reader (or an interrupted render) never sees a half-written image.

use std::fs;
use std::io::{BufWriter, Cursor, Seek, Write};
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use exr::prelude::{
    Blocks, ChannelDescription, Compression, Encoding, Image, Layer, LayerAttributes, LineOrder,
    SampleType, SpecificChannels, Vec2, WritableImage,
};

use crate::aov::{Buffer, Frame, PixelRecord, NO_OBJECT};
use crate::error::Error;

/// The name of the EXR file that holds every buffer of a render.
pub const EXR_FILE: &str = "buffers.exr";

/// Write `frame` into the folder `dir` (created if needed): one PNG per buffer and
/// [`EXR_FILE`], committed together (see [`Pending`]). Returns the files written.
pub fn write_frame(frame: &Frame, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut pending = Pending::new();
    pending.folder(dir)?;
    let paths = pending.frame(frame, dir)?;
    pending.commit()?;
    Ok(paths)
}

/// Write `bytes` to `path` through a temporary file in the same folder, renamed
/// into place once complete (see [`Pending`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let mut pending = Pending::new();
    pending.file(path, bytes)?;
    pending.commit()
}

/// Check a folder that raystep names itself inside the output folder (a stage's):
/// refused if a symbolic link stands at its name (raystep would write, and remove
/// stale buffers, in the link's target, outside the output folder) or anything
/// else that is not a folder.
pub fn check_own_folder(dir: &Path) -> Result<(), Error> {
    let refuse = |message: &str| {
        Err(Error::Output {
            path: dir.to_path_buf(),
            message: format!("{message}; remove it, or give another --out"),
        })
    };
    match fs::symlink_metadata(dir) {
        Ok(m) if m.file_type().is_symlink() => refuse(
            "it is a symbolic link, and raystep writes its own folders only in the output \
             folder, never through a link",
        ),
        Ok(m) if !m.is_dir() => {
            refuse("it is not a folder, and raystep writes a stage's files here")
        }
        _ => Ok(()),
    }
}

/// The files a render of `stages` puts in `dir`: one PNG per buffer it has, and
/// [`EXR_FILE`].
pub fn frame_files(dir: &Path, stages: crate::stages::Stages) -> Vec<PathBuf> {
    Buffer::ALL
        .into_iter()
        .filter(|b| b.written(stages))
        .map(|b| dir.join(format!("{}.png", b.name())))
        .chain([dir.join(EXR_FILE)])
        .collect()
}

/// Refuse, before anything is rendered, a final name at which a folder stands:
/// the commit would have to refuse it after the render (see [`Pending::commit`]).
pub fn check_final_names(paths: &[PathBuf]) -> Result<(), Error> {
    for path in paths {
        if fs::symlink_metadata(path).is_ok_and(|m| m.is_dir()) {
            return Err(Error::Output {
                path: path.clone(),
                message: "a folder stands at this name, where raystep puts a file of its own; \
                          nothing was changed: move the folder, or give another --out"
                    .into(),
            });
        }
    }
    Ok(())
}

/// Output files written under temporary names, waiting to be renamed into place
/// together by [`Pending::commit`].
///
/// Until the commit, no file a reader (or an earlier render) owns is touched: each
/// file is first written in full beside its final name, as
/// `.NAME.PID.NONCE.raystep.tmp`, a name no one can guess and made only where
/// nothing has it. The commit renames them all (and removes the buffer
/// files of an earlier render that this one does not have), which takes a few
/// milliseconds even for `raystep stages`. Dropped without a commit (after an
/// error, or Ctrl-C, which [`Pending::commit`] checks for), it removes its
/// temporary files and the folders it created, so the output folder holds what it
/// held before. A killed process cannot clean up: the next write into the same
/// folder removes the temporary files whose process is gone.
#[derive(Debug, Default)]
pub struct Pending {
    /// (temporary, final) paths, in the order written.
    files: Vec<(PathBuf, PathBuf)>,
    /// Files of an earlier render that the commit removes.
    stale: Vec<PathBuf>,
    /// Folders created for this write, outermost first.
    created: Vec<PathBuf>,
    /// Every folder written into: its path, the folder itself held open, and
    /// which folder it was (device and inode), to notice one moved or replaced
    /// during the render and to clean up inside it all the same.
    folders: Vec<(PathBuf, Option<fs::File>, Option<Identity>)>,
    /// How [`Pending::frame`] encodes the colour pictures.
    png: PngEncoding,
}

/// Which file or folder stands at a path: its device and inode.
type Identity = (u64, u64);

/// The device and inode of what stands at `path` (not following a link).
fn identity(path: &Path) -> Option<Identity> {
    use std::os::unix::fs::MetadataExt;
    fs::symlink_metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

impl Pending {
    /// Nothing written yet.
    pub fn new() -> Pending {
        Pending::default()
    }

    /// The same, with the colour pictures of [`Pending::frame`] encoded as `png`
    /// says (`--png`; linear without it).
    pub fn with_png(mut self, png: PngEncoding) -> Pending {
        self.png = png;
        self
    }

    /// Make sure `dir` is a folder that files can be written in: create it (and
    /// the folders above it) if needed, and try a file in it, so that a folder
    /// that cannot be written fails now, not after a long render. Temporary files
    /// that a killed raystep left in it are removed.
    pub fn folder(&mut self, dir: &Path) -> Result<(), Error> {
        let fail = |message: String| Error::Output {
            path: dir.to_path_buf(),
            message,
        };
        if dir.exists() && !dir.is_dir() {
            return Err(fail(
                "it is a file, not a folder; give --out a folder".into(),
            ));
        }
        let missing: Vec<&Path> = dir
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .collect();
        for folder in missing.into_iter().rev() {
            match fs::create_dir(folder) {
                Ok(()) => {
                    crate::interrupt::made(folder, true);
                    self.created.push(folder.to_path_buf());
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && folder.is_dir() => {}
                Err(e) => return Err(fail(format!("cannot create the output folder: {e}"))),
            }
        }
        let held = fs::File::open(dir).ok();
        self.folders.push((dir.to_path_buf(), held, identity(dir)));
        let probe = temporary_name(&dir.join("probe"));
        create_new(&probe)
            .and_then(|_| fs::remove_file(&probe))
            .map_err(|e| fail(format!("cannot write files in the output folder: {e}")))?;
        remove_abandoned_temporaries(dir);
        Ok(())
    }

    /// Write `bytes` to a temporary name beside `path`.
    pub fn file(&mut self, path: &Path, bytes: &[u8]) -> Result<(), Error> {
        let temporary = self.register(path);
        write_new(&temporary, bytes).map_err(|e| Error::Output {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Write the files of `frame` into `dir` (a [`Pending::folder`]): one PNG per
    /// buffer and [`EXR_FILE`], encoded in parallel. Buffer files of an earlier
    /// render that this frame does not have (say `depth.png` after a `rays`-only
    /// render) will be removed by the commit. Returns the files' final paths.
    ///
    /// The EXR file is streamed from the frame to its file, scan line by scan
    /// line, so no copy of the buffers is made: at 1920 × 1080 the frame's 100 MB
    /// is most of what the whole render holds in memory.
    pub fn frame(&mut self, frame: &Frame, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        let buffers: Vec<Buffer> = frame.buffers().collect();
        let mut paths: Vec<PathBuf> = buffers
            .iter()
            .map(|b| dir.join(format!("{}.png", b.name())))
            .collect();
        paths.push(dir.join(EXR_FILE));
        let temporaries: Vec<PathBuf> = paths.iter().map(|p| self.register(p)).collect();
        let fail = |path: &Path, message: String| Error::Output {
            path: path.to_path_buf(),
            message,
        };
        // Encode and write every file in parallel (each encoder is deterministic).
        let png = self.png;
        let (pngs, exr) = rayon::join(
            || {
                buffers
                    .par_iter()
                    .zip(&paths)
                    .zip(&temporaries)
                    .map(|((&b, path), temporary)| {
                        write_new(temporary, &png_bytes_as(frame, b, png))
                            .map_err(|e| fail(path, e.to_string()))
                    })
                    .collect::<Result<Vec<()>, Error>>()
            },
            || write_exr(frame, &temporaries[buffers.len()], &paths[buffers.len()]),
        );
        pngs.and(exr)?;
        self.stale.extend(
            Buffer::ALL
                .into_iter()
                .filter(|&b| !frame.has(b))
                .map(|b| dir.join(format!("{}.png", b.name()))),
        );
        Ok(paths)
    }

    /// Remove `path`, a file of an earlier run that this one does not write, when
    /// the rest is committed.
    pub fn remove_on_commit(&mut self, path: &Path) {
        self.stale.push(path.to_path_buf());
    }

    /// Put every file into place and remove the stale ones, all or nothing;
    /// refused with [`Error::Interrupted`] (and everything removed) after Ctrl-C.
    ///
    /// Anything but a file (or a link) at a final name, a folder say, is refused
    /// before a single rename. Then each old file (a stale one, or one a new file
    /// replaces) is first moved aside under a temporary name, and each new file
    /// renamed into place; should one of those steps fail, everything done is
    /// undone in reverse, so the folder holds exactly the old files. Only when all
    /// succeeded are the old files, now aside, removed.
    pub fn commit(mut self) -> Result<(), Error> {
        // Held while the files are renamed: a watchdog after Ctrl-C waits for it.
        let mut noted = crate::interrupt::files();
        crate::error::check_interrupt()?;
        if let Some((dir, _, _)) = self.folders.iter().find(|(d, _, was)| identity(d) != *was) {
            return Err(Error::Output {
                path: dir.clone(),
                message: "this folder was moved or replaced while raystep rendered into it; \
                          nothing was put in place, and the files begun in it were removed"
                    .into(),
            });
        }
        let finals: Vec<PathBuf> = self.files.iter().map(|(_, path)| path.clone()).collect();
        check_final_names(&finals)?;
        let present = |path: &Path| fs::symlink_metadata(path).ok();
        let stale: Vec<PathBuf> = std::mem::take(&mut self.stale)
            .into_iter()
            .filter(|p| present(p).is_some_and(|m| !m.is_dir()))
            .collect();
        // Each step, to undo in reverse: an old file moved aside (its name, and
        // where it went), or a new file put in place.
        enum Step {
            Aside(PathBuf, PathBuf),
            Placed(PathBuf, PathBuf),
        }
        let mut steps = Vec::new();
        let mut outcome = Ok(());
        let aside = |path: &Path, steps: &mut Vec<Step>| -> std::io::Result<()> {
            let backup = temporary_name(path);
            fs::rename(path, &backup)?;
            steps.push(Step::Aside(path.to_path_buf(), backup));
            Ok(())
        };
        for path in &stale {
            if let Err(e) = aside(path, &mut steps) {
                outcome = Err((
                    path.clone(),
                    format!("cannot remove this file of an earlier render: {e}"),
                ));
                break;
            }
        }
        if outcome.is_ok() {
            for (temporary, path) in &self.files {
                let placed = match present(path) {
                    Some(_) => aside(path, &mut steps),
                    None => Ok(()),
                }
                .and_then(|()| fs::rename(temporary, path));
                match placed {
                    Ok(()) => steps.push(Step::Placed(temporary.clone(), path.clone())),
                    Err(e) => {
                        outcome = Err((path.clone(), e.to_string()));
                        break;
                    }
                }
            }
        }
        if let Err((path, message)) = outcome {
            // Undo, newest first: a new file goes back to its temporary name (which
            // the drop removes), an old one back to its own.
            for step in steps.iter().rev() {
                let _ = match step {
                    Step::Placed(temporary, path) => fs::rename(path, temporary),
                    Step::Aside(path, backup) => fs::rename(backup, path),
                };
            }
            return Err(Error::Output {
                path,
                message: format!("{message}; nothing was changed"),
            });
        }
        for step in &steps {
            match step {
                Step::Aside(_, backup) => {
                    let _ = fs::remove_file(backup);
                }
                Step::Placed(temporary, _) => noted.retain(|(t, _)| t != temporary),
            }
        }
        self.files.clear();
        // The folders made for the files now hold them.
        noted.retain(|(p, _)| !self.created.contains(p));
        self.created.clear();
        crate::interrupt::committed();
        Ok(())
    }

    /// Where the temporary file `temporary` is now: at its path, unless its folder
    /// was moved or replaced since, and then inside the folder held open (through
    /// `/proc/self/fd` on Linux; elsewhere the path is all there is).
    fn where_now(&self, temporary: &Path) -> PathBuf {
        let (Some(dir), Some(name)) = (temporary.parent(), temporary.file_name()) else {
            return temporary.to_path_buf();
        };
        for (folder, held, was) in &self.folders {
            if folder == dir && identity(folder) != *was {
                if let Some(held) = held {
                    use std::os::fd::AsRawFd;
                    let through = Path::new("/proc/self/fd")
                        .join(held.as_raw_fd().to_string())
                        .join(name);
                    if through.parent().is_some_and(Path::exists) {
                        return through;
                    }
                }
            }
        }
        temporary.to_path_buf()
    }

    /// Note that `path` is being written, and return its temporary name.
    fn register(&mut self, path: &Path) -> PathBuf {
        let temporary = temporary_name(path);
        crate::interrupt::made(&temporary, false);
        self.files.push((temporary.clone(), path.to_path_buf()));
        temporary
    }
}

impl Drop for Pending {
    /// Not committed: remove the temporary files, then the folders created for
    /// them if they are empty (`remove_dir` refuses a folder that is not).
    fn drop(&mut self) {
        for (temporary, _) in &self.files {
            let _ = fs::remove_file(self.where_now(temporary));
            crate::interrupt::forget(temporary);
        }
        for folder in self.created.iter().rev() {
            // Only the folder raystep made: not one that took its name since.
            if self
                .folders
                .iter()
                .all(|(d, _, was)| d != folder || identity(d) == *was)
            {
                let _ = fs::remove_dir(folder);
            }
            crate::interrupt::forget(folder);
        }
    }
}

/// The suffix of every temporary file raystep writes.
const TEMPORARY_SUFFIX: &str = ".raystep.tmp";

/// `dir/.NAME.PID.NONCE.raystep.tmp` for `dir/NAME`: hidden, beside its final name
/// (so the rename stays on one file system), naming the process that writes it,
/// and with 64 bits no one can guess ([`nonce`]), so that nobody can plant a link
/// at the name beforehand; it is created with [`create_new`] all the same.
fn temporary_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("output");
    let (pid, nonce) = (std::process::id(), nonce());
    path.with_file_name(format!(".{name}.{pid}.{nonce:016x}{TEMPORARY_SUFFIX}"))
}

/// 64 bits that differ on every call and in every process: the hash of a counter
/// under the standard library's randomly keyed hasher (keyed from the system's
/// random source once per process). For temporary names only; no render uses it.
fn nonce() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNT: AtomicU64 = AtomicU64::new(0);
    static KEYS: std::sync::OnceLock<std::collections::hash_map::RandomState> =
        std::sync::OnceLock::new();
    let mut hasher = KEYS.get_or_init(Default::default).build_hasher();
    hasher.write_u64(COUNT.fetch_add(1, Ordering::Relaxed));
    hasher.finish()
}

/// Create `path` for writing, failing if anything (a file, a folder, a symbolic
/// link, even a dangling one) already has that name: a temporary file is never
/// opened through someone else's link.
fn create_new(path: &Path) -> std::io::Result<fs::File> {
    fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
}

/// Write `bytes` to a new file `path` ([`create_new`]).
fn write_new(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    create_new(path)?.write_all(bytes)
}

/// Remove the temporary files in `dir` that a raystep process which no longer
/// runs left behind (it was killed before it could clean up). Only on Linux, where
/// `/proc` tells whether a process runs; elsewhere they stay, harmless and hidden.
fn remove_abandoned_temporaries(dir: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        // `.NAME.PID.NONCE.raystep.tmp` (or `.NAME.PID.raystep.tmp`, before the
        // names had a nonce).
        let Some(pid) = name
            .strip_prefix('.')
            .and_then(|n| n.strip_suffix(TEMPORARY_SUFFIX))
            .map(|n| match n.rsplit_once('.') {
                Some((rest, nonce))
                    if nonce.len() == 16 && u64::from_str_radix(nonce, 16).is_ok() =>
                {
                    rest
                }
                _ => n,
            })
            .and_then(|n| n.rsplit_once('.'))
            .and_then(|(_, pid)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = fs::remove_file(entry.path());
        }
    }
}

// ANCHOR: visualise
/// The 8-bit picture of one buffer, as the PNG files show it:
///
/// - `beauty`: the colour, rounded to 8 bits;
/// - `direction`, `normal`: each unit-vector component mapped from [−1, 1] to [0, 1];
/// - `depth`: grey, `nearest depth / depth`, so the nearest hit is white and
///   distance darkens it (1/depth keeps near detail visible when the floor runs
///   far away);
/// - `shadow`: white lit, black in shadow;
/// - `object`: a colour of its own for each object (hues a golden angle apart);
/// - `ambient`, `diffuse`, `specular`: the term's colour, clipped to [0, 1];
/// - `bounces`, `rays`: a heat map on matplotlib's magma, from black (none)
///   through purple and orange to pale yellow (the most of any pixel in the frame).
///
/// Pixels whose primary ray missed everything are drawn in a blue checkerboard in
/// the buffers of the first hit (`depth` to `specular`): no hit value can be
/// mistaken for them.
pub fn visualise(frame: &Frame, buffer: Buffer) -> Vec<u8> {
    visualise_as(frame, buffer, PngEncoding::Linear)
}

/// The 8-bit picture of one buffer, as [`visualise`] draws it, its colour
/// pictures encoded as `png` says (see [`PngEncoding`]).
pub fn visualise_as(frame: &Frame, buffer: Buffer, png: PngEncoding) -> Vec<u8> {
    let tone = |colour: [f32; 3]| match png {
        PngEncoding::Linear => colour,
        PngEncoding::Srgb => colour.map(srgb_encode),
    };
    // Each statistic is a pass over the whole frame (100 MB at 1920 × 1080), so
    // only the buffer that shows it computes it.
    let largest = |count: fn(&PixelRecord) -> u32| frame.pixels.par_iter().map(count).max();
    let (nearest, most) = match buffer {
        Buffer::Depth => {
            let depths = frame.pixels.par_iter().map(|p| p.depth);
            (depths.reduce(|| f32::INFINITY, f32::min), 0)
        }
        Buffer::Bounces => (0.0, largest(|p| p.bounces).unwrap_or(0)),
        Buffer::Rays => (0.0, largest(|p| p.rays).unwrap_or(0)),
        _ => (0.0, 0),
    };
    // The heat map's colour of every count from 0 to `most`, worked out once: per
    // pixel, the colour map's own lookup costs about 35 ns (a table, 0.6 ns).
    let heats: Vec<[f32; 3]> = match most {
        0..=65_536 => (0..=most).map(|k| heat(k, most)).collect(),
        _ => Vec::new(),
    };
    let hot = |count: u32| {
        heats
            .get(count as usize)
            .copied()
            .unwrap_or_else(|| heat(count, most))
    };
    picture(frame, |row, col, p| match buffer {
        Buffer::Beauty => tone(p.colour),
        Buffer::Direction => unit_vector_colour(frame.direction(row, col)),
        Buffer::Bounces => hot(p.bounces),
        Buffer::Rays => hot(p.rays),
        _ if !p.is_hit() => miss_colour(row, col),
        Buffer::Depth => [nearest / p.depth; 3],
        Buffer::Normal => unit_vector_colour(p.normal),
        Buffer::Shadow => [p.shadow; 3],
        Buffer::Object => object_colour(p.object),
        Buffer::Ambient => tone(frame.terms(p)[0]),
        Buffer::Diffuse => tone(frame.terms(p)[1]),
        Buffer::Specular => tone(frame.terms(p)[2]),
    })
}

/// The 8-bit RGB bytes of `colour(row, col, record)` for every pixel, row by row
/// in parallel (each row's bytes depend on that row alone).
fn picture(frame: &Frame, colour: impl Fn(u32, u32, &PixelRecord) -> [f32; 3] + Sync) -> Vec<u8> {
    let width = frame.width as usize;
    let mut rgb = vec![0; frame.pixels.len() * 3];
    rgb.par_chunks_mut(width * 3)
        .zip(frame.pixels.par_chunks(width))
        .enumerate()
        .for_each(|(row, (bytes, pixels))| {
            for (col, (out, p)) in bytes.chunks_exact_mut(3).zip(pixels).enumerate() {
                out.copy_from_slice(&colour(row as u32, col as u32, p).map(to_byte));
            }
        });
    rgb
}

/// Object `id`'s colour: its hue turns by the golden angle from one object to
/// the next, so neighbours in the file never look alike.
fn object_colour(id: u32) -> [f32; 3] {
    let hue = (0.1 + f64::from(id) * 0.381_966_011_250_105).fract();
    hsv(hue as f32, 0.65, 0.95)
}

/// A colour from hue (0 to 1 around the circle), saturation and value.
fn hsv(hue: f32, saturation: f32, value: f32) -> [f32; 3] {
    let channel = |n: f32| {
        let k = (n + hue * 6.0) % 6.0;
        value - value * saturation * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    [channel(5.0), channel(3.0), channel(1.0)]
}

/// `count` out of `most` on a dark-to-light heat scale: matplotlib's magma, as
/// the `colorous` crate holds it.
fn heat(count: u32, most: u32) -> [f32; 3] {
    let t = f64::from(count) / f64::from(most.max(1));
    let c = colorous::MAGMA.eval_continuous(t);
    // Exact in 8 bits: `to_byte` gives back the crate's bytes.
    [c.r, c.g, c.b].map(|v| f32::from(v) / 255.0)
}

fn unit_vector_colour(v: [f32; 3]) -> [f32; 3] {
    v.map(|c| c * 0.5 + 0.5)
}

fn miss_colour(row: u32, col: u32) -> [f32; 3] {
    if (row / 4 + col / 4) % 2 == 0 {
        [0.10, 0.12, 0.30]
    } else {
        [0.18, 0.22, 0.45]
    }
}

/// A channel from [0, 1] to 8 bits, rounded to the nearest level (clipped first).
pub(crate) fn to_byte(v: f32) -> u8 {
    let scaled = v.clamp(0.0, 1.0) * 255.0;
    // `scaled.round()`, halves away from zero, without the call to the C library's
    // `roundf` that x86-64 makes for it (perf: 7 % of a whole 1080p render).
    // `scaled - whole` is exact, and NaN gives 0 as `round` does.
    let whole = scaled as u8;
    whole + u8::from(scaled - f32::from(whole) >= 0.5)
}
// ANCHOR_END: visualise

/// How `--png` stores the colour pictures' linear values in 8 bits: `beauty` and
/// the Blinn-Phong terms (`ambient`, `diffuse`, `specular`), which hold light.
/// The other pictures are not light (directions, depth ratios, lit or not, ids,
/// counts) and are drawn the same either way; `buffers.exr` is always linear.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PngEncoding {
    /// The values as they are, as the tutorial writes them, in a PNG without a
    /// colour chunk: viewers take the bytes for sRGB, so the picture looks darker
    /// than the light it holds.
    #[default]
    Linear,
    /// Each value through the sRGB transfer function of IEC 61966-2-1, in a PNG
    /// with an sRGB chunk: viewers show the light as rendered.
    Srgb,
}

impl PngEncoding {
    /// Whether `buffer`'s picture holds light, and so changes with the encoding.
    pub fn applies_to(buffer: Buffer) -> bool {
        matches!(
            buffer,
            Buffer::Beauty | Buffer::Ambient | Buffer::Diffuse | Buffer::Specular
        )
    }
}

/// The sRGB transfer function of IEC 61966-2-1, exact and piecewise: linear
/// light `v` in [0, 1] to the value an sRGB display expects, `12.92 v` up to
/// 0.003 130 8 and `1.055 v^(1/2.4) − 0.055` above (values outside [0, 1] are
/// clipped later, by [`to_byte`]).
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The PNG file of one buffer, as bytes (fast compression: these are debug images,
/// written often, read once), linear as the tutorial writes it.
pub fn png_bytes(frame: &Frame, buffer: Buffer) -> Vec<u8> {
    png_bytes_as(frame, buffer, PngEncoding::Linear)
}

/// The PNG file of one buffer, its colour encoded as `png` says: an `sRGB` chunk
/// (perceptual intent) where the bytes are sRGB-encoded, no colour chunk
/// otherwise. Written by the `png` crate with the settings `image` uses for it.
pub fn png_bytes_as(frame: &Frame, buffer: Buffer, png: PngEncoding) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, frame.width, frame.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Adaptive);
    if png == PngEncoding::Srgb && PngEncoding::applies_to(buffer) {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    encoder
        .write_header()
        .and_then(|mut writer| writer.write_image_data(&visualise_as(frame, buffer, png)))
        .expect("encoding a PNG into memory cannot fail");
    bytes
}

// ANCHOR: exr
/// Write the EXR file of a frame to `writer`: one float32 channel per number of
/// every buffer the frame has, named as compositing tools expect them. `R, G, B`:
/// beauty; `dir.X, dir.Y, dir.Z`: ray direction; `Z`: depth (+∞ on a miss);
/// `N.X, N.Y, N.Z`: normal; `shadow`: 1 lit, 0 shadowed, −1 missed; `object`: the
/// object's index, −1 missed; `ambient.R` … `specular.B`: the Blinn-Phong terms;
/// `bounces` and `rays`: counts. The samples are read from the frame as each scan
/// line is written.
pub fn exr_to<W: Write + Seek>(frame: &Frame, writer: W) -> exr::error::UnitResult {
    let size = (frame.width as usize, frame.height as usize);
    // Uncompressed. Float buffers barely compress, and exr's compressors are
    // slow on them: at 1920 × 1080 (23 channels, 191 MB of samples) RLE saved 42 %
    // of the file (110 MB) at about 0.3 s more per render on 2 cores, ZIP 74 %
    // (50 MB) at about 1.1 s more (measured with raystep's release build,
    // 2026-12-01).
    // Scan lines in increasing order keep the bytes the same on every run.
    let encoding = Encoding {
        compression: Compression::Uncompressed,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    // A channel of each buffer the frame has; exr sorts them by name in the file.
    let channel = |buffer: Buffer, name: &str| {
        frame
            .has(buffer)
            .then(|| ChannelDescription::named(name, SampleType::F32))
    };
    let three = |buffer: Buffer, names: [&str; 3]| names.map(|n| channel(buffer, n));
    let [r, g, b] = three(Buffer::Beauty, ["R", "G", "B"]);
    let [dx, dy, dz] = three(Buffer::Direction, ["dir.X", "dir.Y", "dir.Z"]);
    let [nx, ny, nz] = three(Buffer::Normal, ["N.X", "N.Y", "N.Z"]);
    let [ar, ag, ab] = three(Buffer::Ambient, ["ambient.R", "ambient.G", "ambient.B"]);
    let [dr, dg, db] = three(Buffer::Diffuse, ["diffuse.R", "diffuse.G", "diffuse.B"]);
    let [sr, sg, sb] = three(Buffer::Specular, ["specular.R", "specular.G", "specular.B"]);
    let names = (
        r,
        g,
        b,
        dx,
        dy,
        dz,
        channel(Buffer::Depth, "Z"),
        nx,
        ny,
        nz,
        channel(Buffer::Shadow, "shadow"),
        channel(Buffer::Object, "object"),
        ar,
        ag,
        ab,
        dr,
        dg,
        db,
        sr,
        sg,
        sb,
        channel(Buffer::Bounces, "bounces"),
        channel(Buffer::Rays, "rays"),
    );
    let channels = SpecificChannels::new(names, |at: Vec2<usize>| {
        let (row, col) = (at.y() as u32, at.x() as u32);
        let p = frame.at(row, col);
        let d = frame.direction(row, col);
        let [c, n] = [p.colour, p.normal];
        let [a, df, s] = frame.terms(p);
        let object = if p.object == NO_OBJECT {
            -1.0
        } else {
            p.object as f32
        };
        (
            c[0],
            c[1],
            c[2],
            d[0],
            d[1],
            d[2],
            p.depth,
            n[0],
            n[1],
            n[2],
            p.shadow,
            object,
            a[0],
            a[1],
            a[2],
            df[0],
            df[1],
            df[2],
            s[0],
            s[1],
            s[2],
            p.bounces as f32,
            p.rays as f32,
        )
    });
    let layer = Layer::new(size, LayerAttributes::default(), encoding, channels);
    Image::from_layer(layer).write().to_buffered(writer)
}
// ANCHOR_END: exr

/// The EXR file of a frame, as bytes (for tests; renders stream it to the file).
pub fn exr_bytes(frame: &Frame) -> Result<Vec<u8>, Error> {
    let mut bytes = Cursor::new(Vec::new());
    exr_to(frame, &mut bytes).map_err(|e| Error::Output {
        path: PathBuf::from(EXR_FILE),
        message: format!("cannot encode the EXR: {e}"),
    })?;
    Ok(bytes.into_inner())
}

/// Write the EXR file of a frame to `temporary`, reporting errors against `path`.
fn write_exr(frame: &Frame, temporary: &Path, path: &Path) -> Result<(), Error> {
    let fail = |message: String| Error::Output {
        path: path.to_path_buf(),
        message,
    };
    let file = create_new(temporary).map_err(|e| fail(e.to_string()))?;
    let mut writer = BufWriter::new(file);
    exr_to(frame, &mut writer).map_err(|e| fail(format!("cannot write the EXR: {e}")))?;
    writer.flush().map_err(|e| fail(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::to_byte;

    /// The reference rule: clip, scale, round half away from zero.
    fn rounded(v: f32) -> u8 {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }

    #[test]
    fn to_byte_rounds_as_f32_round_does() {
        // Every value a few ulps either side of each half level and each level,
        // where the rounding decides between two levels.
        for k in 0..=510u32 {
            let centre = (k as f32 / 510.0).to_bits();
            for bits in centre.saturating_sub(8)..=centre + 8 {
                let v = f32::from_bits(bits);
                assert_eq!(to_byte(v), rounded(v), "{v:e} ({bits:#x})");
            }
        }
        // Every 997th float from 0 to 1, and what lies outside.
        for bits in (0..=1f32.to_bits()).step_by(997) {
            let v = f32::from_bits(bits);
            assert_eq!(to_byte(v), rounded(v), "{v:e}");
        }
        for v in [-0.0, -1.0, 1.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            assert_eq!(to_byte(v), rounded(v), "{v:e}");
        }
    }
}
