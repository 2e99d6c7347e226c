//! Buffers to files: PNG pictures for eyes, one EXR file with the raw floats.
//!
//! Every file is written under a temporary name and then renamed ([`Pending`]), so
//! a reader (or an interrupted render) never sees a half-written image.

use std::fs;
use std::io::{BufWriter, Cursor, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;

use exr::block::writer::ChunksWriter;
use exr::block::BlockIndex;
use exr::meta::header::Header;
use exr::meta::BlockDescription;
use exr::prelude::{
    ChannelDescription, Compression, ImageAttributes, IntegerBounds, LayerAttributes, LineOrder,
    SampleType, SmallVec, Text, Vec2,
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
    /// How [`Pending::frame`] compresses the EXR file.
    exr: ExrCompression,
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

    /// The same, with the EXR file of [`Pending::frame`] compressed as `exr`
    /// says (`--exr-compression`; uncompressed without it).
    pub fn with_exr(mut self, exr: ExrCompression) -> Pending {
        self.exr = exr;
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
        // A folder written into earlier that has moved since: a folder under it
        // (a stage's) would otherwise be made again at the old path.
        self.check_folders()?;
        if dir.exists() && !dir.is_dir() {
            return Err(fail(
                "it is a file, not a folder; give --out a folder".into(),
            ));
        }
        if dir.as_os_str() == "-" {
            return Err(fail(
                "raystep writes a folder of files, not standard output; give --out a \
                 folder (./- for one named -)"
                    .into(),
            ));
        }
        // A file where a folder above it should be: `--out notes.txt/render`.
        if let Some(file) = dir
            .ancestors()
            .skip(1)
            .find(|a| !a.as_os_str().is_empty() && a.exists() && !a.is_dir())
        {
            return Err(fail(format!(
                "{} is a file, not a folder, so no folder can be made in it",
                file.display()
            )));
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
                Err(e) => {
                    // A parent that exists but takes no new folder (/proc, say)
                    // answers "not found", which reads as if the folder should exist.
                    let parent = folder.parent().filter(|p| !p.as_os_str().is_empty());
                    let why = match parent {
                        Some(p) if e.kind() == std::io::ErrorKind::NotFound && p.is_dir() => {
                            format!("{} does not let a folder be made in it ({e})", p.display())
                        }
                        _ => e.to_string(),
                    };
                    return Err(fail(format!(
                        "cannot create the output folder {}: {why}",
                        folder.display()
                    )));
                }
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
    /// render) will be removed by the commit: those whose channels the earlier
    /// render's [`EXR_FILE`] in `dir` lists ([`earlier_buffers`]), so a file of the
    /// same name that raystep did not write is left alone. Returns the files'
    /// final paths.
    ///
    /// Every file is streamed from the frame in one pass over its records (see
    /// `write_files`), so no copy of the buffers is made: at 1920 × 1080 the
    /// frame's 108 MB is most of what the whole render holds in memory.
    pub fn frame(&mut self, frame: &Frame, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        self.frame_counted(frame, dir, &|_| {})
    }

    /// [`Pending::frame`], telling `rows_written` how many more of the frame's
    /// rows are in every file each time a block of them has been written (in
    /// all, the frame's height), as `render` tells its rows traced: what the
    /// command line's bar counts while the files are written.
    pub fn frame_counted(
        &mut self,
        frame: &Frame,
        dir: &Path,
        rows_written: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<PathBuf>, Error> {
        let buffers: Vec<Buffer> = frame.buffers().collect();
        let mut paths: Vec<PathBuf> = buffers
            .iter()
            .map(|b| dir.join(format!("{}.png", b.name())))
            .collect();
        paths.push(dir.join(EXR_FILE));
        let earlier = earlier_buffers(&dir.join(EXR_FILE));
        let temporaries: Vec<PathBuf> = paths.iter().map(|p| self.register(p)).collect();
        let files = (temporaries.as_slice(), paths.as_slice());
        write_files(frame, &buffers, self.png, self.exr, files, rows_written)?;
        self.stale.extend(
            earlier
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
    /// A folder at a final name is refused before a single rename. Then each old
    /// file (a stale one, or one a new file replaces) is first moved aside under a
    /// temporary name, and each new file renamed into place; should one of those
    /// steps fail, everything done is undone in reverse, so the folder holds
    /// exactly the old files. Only when all succeeded are the old files, now aside,
    /// removed.
    pub fn commit(mut self) -> Result<(), Error> {
        // Held while the files are renamed: a watchdog after Ctrl-C waits for it.
        let mut noted = crate::interrupt::files();
        crate::error::check_interrupt()?;
        self.check_folders()?;
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

    /// Refuse to go on once a folder written into was moved or replaced.
    fn check_folders(&self) -> Result<(), Error> {
        match self.folders.iter().find(|(d, _, was)| identity(d) != *was) {
            Some((dir, _, _)) => Err(Error::Output {
                path: dir.clone(),
                message: "this folder was moved or replaced while raystep rendered into it; \
                          nothing was put in place, and the files begun in it were removed"
                    .into(),
            }),
            None => Ok(()),
        }
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
/// - `position`: each coordinate's fractional part, `P − ⌊P⌋`, as red, green and
///   blue: a ramp that starts again at every whole world unit, so the edges of the
///   colour bands are the lines x, y or z = integer (no picture can hold the
///   floor's far points and the spheres' near ones in one scale; the numbers are in
///   `buffers.exr` and the page);
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
    let palette = Palette::new(frame, png, &[buffer]);
    palette.pictures(&[buffer]).remove(0)
}

/// What the pictures of a frame need besides each pixel's record: the frame's
/// nearest depth and largest counts, found in one pass over the records.
struct Palette<'a> {
    frame: &'a Frame,
    png: PngEncoding,
    /// The nearest depth (`depth`'s white).
    nearest: f32,
    /// The heat maps of `bounces` and `rays`.
    bounces: Heat,
    rays: Heat,
    /// The colour of each object in play ([`object_colour`], three `fmod` a
    /// call).
    objects: Vec<[f32; 3]>,
}

/// A heat map from 0 to `most`, its colours worked out once: per pixel, the
/// colour map's own lookup costs about 35 ns (a table, 0.6 ns).
struct Heat {
    most: u32,
    table: Vec<[f32; 3]>,
}

impl Heat {
    fn new(most: u32) -> Heat {
        let table = match most {
            0..=65_536 => (0..=most).map(|k| heat(k, most)).collect(),
            _ => Vec::new(),
        };
        Heat { most, table }
    }

    fn colour(&self, count: u32) -> [f32; 3] {
        (self.table.get(count as usize).copied()).unwrap_or_else(|| heat(count, self.most))
    }
}

impl<'a> Palette<'a> {
    /// The palette of `frame` for drawing `buffers`: one pass over the records
    /// for the statistics those buffers need (none for most).
    fn new(frame: &'a Frame, png: PngEncoding, buffers: &[Buffer]) -> Palette<'a> {
        let needs = |b: Buffer| buffers.contains(&b);
        let (depth, bounces, rays) = (
            needs(Buffer::Depth),
            needs(Buffer::Bounces),
            needs(Buffer::Rays),
        );
        let (nearest, most_bounces, most_rays) = if depth || bounces || rays {
            frame
                .pixels
                .par_iter()
                .map(|p| (p.depth, p.bounces, p.rays))
                .reduce(
                    || (f32::INFINITY, 0, 0),
                    |a, b| (a.0.min(b.0), a.1.max(b.1), a.2.max(b.2)),
                )
        } else {
            (f32::INFINITY, 0, 0)
        };
        Palette {
            frame,
            png,
            nearest,
            bounces: Heat::new(if bounces { most_bounces } else { 0 }),
            rays: Heat::new(if rays { most_rays } else { 0 }),
            objects: (0..frame.term_colours.len() as u32)
                .map(object_colour)
                .collect(),
        }
    }

    fn tone(&self, colour: [f32; 3]) -> [f32; 3] {
        match self.png {
            PngEncoding::Linear => colour,
            PngEncoding::Srgb => colour.map(srgb_encode),
        }
    }

    /// The 8-bit RGB bytes of each of `buffers`, drawn in one pass over the
    /// records, row by row in parallel (each row's bytes depend on that row
    /// alone): a row's records are read from memory once, and each picture's row
    /// drawn from them in a loop of its own. What several buffers share (the
    /// primary ray, the Blinn-Phong terms) is computed once per pixel.
    fn pictures(&self, buffers: &[Buffer]) -> Vec<Vec<u8>> {
        let frame = self.frame;
        let width = frame.width as usize;
        let mut pictures: Vec<Vec<u8>> = buffers
            .iter()
            .map(|_| vec![0; frame.pixels.len() * 3])
            .collect();
        // Each row of every picture, gathered by row.
        let mut rows: Vec<Vec<&mut [u8]>> = (0..frame.height)
            .map(|_| Vec::with_capacity(buffers.len()))
            .collect();
        for picture in &mut pictures {
            for (row, bytes) in picture.chunks_exact_mut(width * 3).enumerate() {
                rows[row].push(bytes);
            }
        }
        let uses = |wanted: &[Buffer]| buffers.iter().any(|b| wanted.contains(b));
        let rays = uses(&[Buffer::Direction, Buffer::Position]);
        let terms = uses(&[Buffer::Ambient, Buffer::Diffuse, Buffer::Specular]);
        rows.into_par_iter()
            .zip(frame.pixels.par_chunks(width))
            .enumerate()
            .for_each_init(
                || (Vec::new(), Vec::new(), vec![[0.0; 3]; frame.width as usize]),
                |(ray_row, terms_row, colours), (row, (outs, pixels))| {
                    let row = row as u32;
                    ray_row.clear();
                    terms_row.clear();
                    if rays {
                        frame.ray_buffers_row(row, 0..frame.width, ray_row);
                    }
                    if terms {
                        terms_row.extend(pixels.iter().map(|p| frame.terms(p)));
                    }
                    self.draw_rows(buffers, row, pixels, ray_row, terms_row, colours, outs);
                },
            );
        pictures
    }

    /// Row `row` of each of `buffers`' pictures, into `outs` (a row of 8-bit RGB
    /// bytes each), from the row's records and its primary rays and Blinn-Phong
    /// terms (where the buffers use them); `colours` is room for a row of colours.
    #[allow(clippy::too_many_arguments)]
    fn draw_rows<'o>(
        &self,
        buffers: &[Buffer],
        row: u32,
        pixels: &[PixelRecord],
        rays: &[([f32; 3], [f32; 3])],
        terms: &[[[f32; 3]; 3]],
        colours: &mut [[f32; 3]],
        outs: impl IntoIterator<Item = &'o mut [u8]>,
    ) {
        for (out, &buffer) in outs.into_iter().zip(buffers) {
            self.draw_row(buffer, row, pixels, rays, terms, colours);
            // A loop of its own, sixteen values at a time, which the compiler
            // vectorises and stores as one 16-byte register.
            let mut bytes = out.chunks_exact_mut(16);
            let mut values = colours.as_flattened().chunks_exact(16);
            for (b, v) in (&mut bytes).zip(&mut values) {
                let v: &[f32; 16] = v.try_into().expect("sixteen values");
                b.copy_from_slice(&v.map(to_byte));
            }
            let rest = bytes.into_remainder().iter_mut();
            for (byte, &v) in rest.zip(values.remainder()) {
                *byte = to_byte(v);
            }
        }
    }

    /// Draw `buffer`'s row `row` into `out` (a colour a pixel) from the row's
    /// records, and its primary rays and Blinn-Phong terms where the buffer uses
    /// them.
    fn draw_row(
        &self,
        buffer: Buffer,
        row: u32,
        pixels: &[PixelRecord],
        rays: &[([f32; 3], [f32; 3])],
        terms: &[[[f32; 3]; 3]],
        out: &mut [[f32; 3]],
    ) {
        // One loop per buffer, the colour rule known inside it; the buffers of
        // the first hit draw a miss as the checkerboard.
        let tone = |c: [f32; 3]| self.tone(c);
        match buffer {
            Buffer::Beauty => fill_row(out, pixels, &|_, p| tone(p.colour)),
            Buffer::Direction => fill_row(out, pixels, &|col, _| unit_vector_colour(rays[col].0)),
            Buffer::Bounces => fill_row(out, pixels, &|_, p| self.bounces.colour(p.bounces)),
            Buffer::Rays => fill_row(out, pixels, &|_, p| self.rays.colour(p.rays)),
            Buffer::Depth => fill_row(
                out,
                pixels,
                &first_hit(row, &|_, p| [self.nearest / p.depth; 3]),
            ),
            Buffer::Normal => fill_row(
                out,
                pixels,
                &first_hit(row, &|_, p| unit_vector_colour(p.normal)),
            ),
            Buffer::Position => fill_row(
                out,
                pixels,
                &first_hit(row, &|col, _| rays[col].1.map(fraction)),
            ),
            Buffer::Shadow => fill_row(out, pixels, &first_hit(row, &|_, p| [p.shadow; 3])),
            Buffer::Object => fill_row(
                out,
                pixels,
                &first_hit(row, &|_, p| {
                    (self.objects.get(p.object as usize).copied())
                        .unwrap_or_else(|| object_colour(p.object))
                }),
            ),
            Buffer::Ambient => {
                fill_row(out, pixels, &first_hit(row, &|col, _| tone(terms[col][0])))
            }
            Buffer::Diffuse => {
                fill_row(out, pixels, &first_hit(row, &|col, _| tone(terms[col][1])))
            }
            Buffer::Specular => {
                fill_row(out, pixels, &first_hit(row, &|col, _| tone(terms[col][2])))
            }
        }
    }
}

/// Fill a picture's row with `colour(column, record)`.
#[inline(always)]
fn fill_row(
    out: &mut [[f32; 3]],
    pixels: &[PixelRecord],
    colour: &impl Fn(usize, &PixelRecord) -> [f32; 3],
) {
    for (col, (c, p)) in out.iter_mut().zip(pixels).enumerate() {
        *c = colour(col, p);
    }
}

/// `colour` where the primary ray hit something, the checkerboard of a miss
/// elsewhere (on row `row`).
#[inline(always)]
fn first_hit<'a>(
    row: u32,
    colour: &'a impl Fn(usize, &PixelRecord) -> [f32; 3],
) -> impl Fn(usize, &PixelRecord) -> [f32; 3] + 'a {
    move |col, p| {
        if p.is_hit() {
            colour(col, p)
        } else {
            miss_colour(row, col as u32)
        }
    }
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

/// 2²³: from here up every float32 is a whole number (`fraction`, `to_byte`).
const TWO_23: f32 = 8_388_608.0;

/// `v − ⌊v⌋`, the place of `v` within its unit cell, 0 where `v` is not finite.
/// The whole part is taken by a cast to an integer, which the compiler runs four
/// values at a time (`floor` is a call to the C library's `floorf` on x86-64, one
/// value at a time); from 2²³ up every float32 is whole.
fn fraction(v: f32) -> f32 {
    if v.abs() < TWO_23 {
        let truncated = v as i32 as f32;
        // (Plus 0 makes −0 into +0, as `v - v.floor()` does.)
        let floor = if truncated > v {
            truncated - 1.0
        } else {
            truncated
        };
        (v - floor) + 0.0
    } else {
        0.0
    }
}

fn unit_vector_colour(v: [f32; 3]) -> [f32; 3] {
    v.map(|c| c * 0.5 + 0.5)
}

fn miss_colour(row: u32, col: u32) -> [f32; 3] {
    if (row / 4 + col / 4).is_multiple_of(2) {
        [0.10, 0.12, 0.30]
    } else {
        [0.18, 0.22, 0.45]
    }
}

/// A channel from [0, 1] to 8 bits, rounded to the nearest level (clipped first).
pub(crate) fn to_byte(v: f32) -> u8 {
    // Clipped to [0, 1], a NaN to 0 (as `round` would make of it).
    // (Two comparisons, which the compiler makes one `maxps` and one `minps`.)
    let clipped = if v > 0.0 { v } else { 0.0 };
    let scaled = if clipped < 1.0 { clipped } else { 1.0 } * 255.0;
    // `scaled.round()`, halves away from zero, in float arithmetic only, which
    // the compiler runs four values at a time in a loop of `to_byte`s (`round` is
    // a call to the C library's `roundf` on x86-64, and a cast to an integer one
    // value at a time). Rounding is the whole part of `scaled` plus one half, but
    // 0.499 999 97 + 0.5 rounds up to 1 in float32; plus the float just below one
    // half is right for every float from 0 to 255 `scaled` can be (the test below
    // tries them all). Adding 2²³ rounds that sum to the nearest whole number, in
    // the low bits of the result; one less where that went up: the whole part.
    const BELOW_HALF: f32 = 0.499_999_97;
    let sum = scaled + BELOW_HALF;
    let nearest = sum + TWO_23;
    let went_up = nearest - TWO_23 > sum;
    (nearest.to_bits() - u32::from(went_up)) as u8
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
/// clipped later, by `to_byte`).
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
    encode_png(frame, buffer, png, &visualise_as(frame, buffer, png))
}

/// The PNG file of `buffer`'s picture `rgb` (see [`png_bytes_as`]): encoded as
/// the files of a render are, by a stream of [`PNG_CHUNK`]-sized `IDAT` chunks,
/// so that these bytes are the file's (the studio's `/api/render` promises it).
fn encode_png(frame: &Frame, buffer: Buffer, png: PngEncoding, rgb: &[u8]) -> Vec<u8> {
    // The stream owns what it writes to: a buffer it shares with this function.
    #[derive(Clone, Default)]
    struct Shared(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);
    impl Write for Shared {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            self.0.borrow_mut().extend_from_slice(bytes);
            Ok(bytes.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let bytes = Shared::default();
    png_encoder(frame, buffer, png, bytes.clone())
        .write_header()
        .and_then(|writer| writer.into_stream_writer_with_size(PNG_CHUNK))
        .and_then(|mut stream| {
            stream.write_all(rgb)?;
            stream.finish()
        })
        .expect("encoding a PNG into memory cannot fail");
    bytes.0.take()
}

/// The PNG encoder of `buffer`'s picture, writing to `out`: 8-bit RGB, fast
/// compression (these are debug images, written often, read once), an `sRGB`
/// chunk where `png` encoded the bytes so.
fn png_encoder<W: Write>(
    frame: &Frame,
    buffer: Buffer,
    png: PngEncoding,
    out: W,
) -> png::Encoder<'static, W> {
    let mut encoder = png::Encoder::new(out, frame.width, frame.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Paeth);
    if png == PngEncoding::Srgb && PngEncoding::applies_to(buffer) {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    encoder
}

/// How `--exr-compression` stores `buffers.exr`: the lossless schemes of
/// OpenEXR that the `exr` crate writes (PXR24 and B44 would round float32
/// samples). Every block is compressed in parallel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ExrCompression {
    /// Uncompressed: the fastest to write and to read, the largest file.
    #[default]
    None,
    /// Run-length encoding of each scan line's bytes.
    Rle,
    /// Deflate, one scan line per block (OpenEXR's ZIPS).
    Zips,
    /// Deflate, 16 scan lines per block (OpenEXR's ZIP).
    Zip,
    /// Wavelet and Huffman coding, 32 scan lines per block (OpenEXR's PIZ).
    Piz,
}

impl ExrCompression {
    fn scheme(self) -> Compression {
        match self {
            ExrCompression::None => Compression::Uncompressed,
            ExrCompression::Rle => Compression::RLE,
            ExrCompression::Zips => Compression::ZIP1,
            ExrCompression::Zip => Compression::ZIP16,
            ExrCompression::Piz => Compression::PIZ,
        }
    }
}

// ANCHOR: exr
/// The channels of `buffers.exr`, each with the buffer it belongs to, named so
/// that Blender, Nuke, tev and OpenImageIO read every one: `R G B` and `Z` as
/// the standard colour and depth, every other channel `layer.channel` (Blender's
/// multilayer reader drops a channel whose name has no dot, or whose last part is
/// more than one letter it does not know, with "unknown channel token").
/// Vectors are `X Y Z`, colours `R G B`, and a buffer of one value has the one
/// channel `X`, as Blender's own `IndexOB.X`. The order here is the order of
/// [`exr_samples`]; the file lists them sorted by name.
pub const EXR_CHANNELS: [(&str, Buffer); 26] = [
    ("R", Buffer::Beauty),
    ("G", Buffer::Beauty),
    ("B", Buffer::Beauty),
    ("dir.X", Buffer::Direction),
    ("dir.Y", Buffer::Direction),
    ("dir.Z", Buffer::Direction),
    ("Z", Buffer::Depth),
    ("N.X", Buffer::Normal),
    ("N.Y", Buffer::Normal),
    ("N.Z", Buffer::Normal),
    ("P.X", Buffer::Position),
    ("P.Y", Buffer::Position),
    ("P.Z", Buffer::Position),
    ("shadow.X", Buffer::Shadow),
    ("object.X", Buffer::Object),
    ("ambient.R", Buffer::Ambient),
    ("ambient.G", Buffer::Ambient),
    ("ambient.B", Buffer::Ambient),
    ("diffuse.R", Buffer::Diffuse),
    ("diffuse.G", Buffer::Diffuse),
    ("diffuse.B", Buffer::Diffuse),
    ("specular.R", Buffer::Specular),
    ("specular.G", Buffer::Specular),
    ("specular.B", Buffer::Specular),
    ("bounces.X", Buffer::Bounces),
    ("rays.X", Buffer::Rays),
];

/// The buffers an earlier render wrote beside the EXR file at `path`: those whose
/// channels ([`EXR_CHANNELS`]) its header lists. None when there is no regular
/// file there (a link, a folder or a FIFO is not read) or it is not an EXR file
/// that can be read: a `depth.png` in a folder that never held raystep's
/// `buffers.exr` is the user's own.
pub fn earlier_buffers(path: &Path) -> Vec<Buffer> {
    if !fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
        return Vec::new();
    }
    let Ok(meta) = exr::meta::MetaData::read_from_file(path, false) else {
        return Vec::new();
    };
    let names: Vec<String> = meta
        .headers
        .iter()
        .flat_map(|h| h.channels.list.iter().map(|c| c.name.to_string()))
        .collect();
    Buffer::ALL
        .into_iter()
        .filter(|b| {
            EXR_CHANNELS
                .iter()
                .any(|(name, of)| of == b && names.iter().any(|n| n == name))
        })
        .collect()
}

/// Every sample of pixel (`row`, `col`), in the order of [`EXR_CHANNELS`]:
/// beauty, direction, depth (+∞ on a miss), normal, position (`(0, 0, 0)` on a
/// miss), shadow (1 lit, 0 shadowed, −1 missed), object (its index, −1 missed),
/// the Blinn-Phong terms, bounces and rays.
pub fn exr_samples(frame: &Frame, row: u32, col: u32) -> [f32; 26] {
    let p = frame.at(row, col);
    let (ray, terms) = (frame.ray_buffers(row, col), frame.terms(p));
    std::array::from_fn(|k| exr_sample(k, p, &ray, &terms))
}

/// Sample `k` of [`exr_samples`], from the pixel's record, its primary ray's
/// direction and position ([`Frame::ray_buffers`]) and its Blinn-Phong terms
/// ([`Frame::terms`]).
#[inline(always)]
fn exr_sample(
    k: usize,
    p: &PixelRecord,
    (direction, position): &([f32; 3], [f32; 3]),
    terms: &[[f32; 3]; 3],
) -> f32 {
    match k {
        0..=2 => p.colour[k],
        3..=5 => direction[k - 3],
        6 => p.depth,
        7..=9 => p.normal[k - 7],
        10..=12 => position[k - 10],
        13 => p.shadow,
        14 if p.object == NO_OBJECT => -1.0,
        14 => p.object as f32,
        15..=23 => terms[(k - 15) / 3][(k - 15) % 3],
        24 => p.bounces as f32,
        _ => p.rays as f32,
    }
}

/// Write the EXR file of a frame to `writer`: one float32 channel per number of
/// every buffer the frame has ([`EXR_CHANNELS`]), in scan lines, compressed as
/// `compression` says (see `stream_files`).
pub fn exr_to<W: Write + Seek + Send>(
    frame: &Frame,
    writer: W,
    compression: ExrCompression,
) -> exr::error::UnitResult {
    let failed = Mutex::new(None);
    stream_files(
        frame,
        writer,
        compression,
        None,
        (&mut [], &failed),
        &|_| {},
    )
}

/// The pictures [`stream_files`] writes beside the EXR: how to draw them, which
/// buffers, and a PNG encoder for each that takes the picture row by row.
type Pictures<'a, 'b> = Option<(&'a Palette<'b>, &'a [Buffer])>;

/// A PNG file being written, its picture's rows handed to it in order.
type PngStream = png::StreamWriter<'static, BufWriter<fs::File>>;

/// The PNG streams [`stream_files`] writes the pictures to, and where a stream
/// that fails leaves its index and error.
type PngStreams<'a> = (
    &'a mut [PngStream],
    &'a Mutex<Option<(usize, std::io::Error)>>,
);

/// Write the EXR file of a frame to `writer`, and each picture of `pictures` to
/// its PNG stream in `streams`, in one pass over the records: block of scan
/// lines after block (1 to 32 lines, as the compression groups them), each
/// line's primary rays and Blinn-Phong terms computed once for the EXR's
/// channels and every picture. A few dozen blocks are laid out and compressed
/// in parallel on rayon's threads while the blocks before them are written:
/// the EXR's chunks in order, and each picture's rows to its PNG stream, the
/// files in parallel. Every file's bytes are the same whatever the thread count.
/// A PNG stream that fails leaves its index and error in `failed`. Each time a
/// block has been written to every file, `rows_written` is told its lines.
fn stream_files<W: Write + Seek + Send>(
    frame: &Frame,
    writer: W,
    compression: ExrCompression,
    pictures: Pictures,
    (streams, failed): PngStreams,
    rows_written: &(dyn Fn(u64) + Sync),
) -> exr::error::UnitResult {
    let size = Vec2(frame.width as usize, frame.height as usize);
    let mut channels: Vec<(&str, usize)> = (EXR_CHANNELS.iter().enumerate())
        .filter(|(_, (_, buffer))| frame.has(*buffer))
        .map(|(index, (name, _))| (*name, index))
        .collect();
    // OpenEXR wants them sorted by name.
    channels.sort_unstable_by_key(|(name, _)| name.as_bytes());
    let descriptions = channels
        .iter()
        .map(|(name, _)| ChannelDescription::named(*name, SampleType::F32))
        .collect();
    // Scan lines in increasing order keep the bytes the same on every run.
    let descriptions: SmallVec<[ChannelDescription; 5]> = descriptions;
    let header = Header::new(Text::from(""), size, descriptions)
        .with_attributes(LayerAttributes::default())
        .with_shared_attributes(ImageAttributes::new(IntegerBounds::from_dimensions(size)))
        .with_encoding(
            compression.scheme(),
            BlockDescription::ScanLines,
            LineOrder::Increasing,
        );
    let order: Vec<usize> = channels.iter().map(|(_, index)| *index).collect();
    let picture_count = pictures.map_or(0, |(_, buffers)| buffers.len());
    exr::block::write(
        writer,
        SmallVec::from_iter([header]),
        true,
        |meta, chunks| {
            let blocks: Vec<(usize, BlockIndex)> =
                exr::block::enumerate_ordered_header_block_indices(&meta.headers).collect();
            let lines = blocks.first().map_or(1, |(_, b)| b.pixel_size.height());
            // About 4 MB of blocks in the making, as many being written, and a
            // block per thread at least: at 1920 × 1080, 15 lines of the EXR and
            // of every picture, 8 MB beside the frame's 108 MB.
            let line_bytes = size.width() * (order.len() * 4 + picture_count * 3);
            let window = (4 << 20) / (line_bytes * lines).max(1);
            let window = window.clamp(rayon::current_num_threads(), 256);
            let make = |some: &[(usize, BlockIndex)]| -> exr::error::Result<Vec<Block>> {
                some.par_iter()
                    .map(|&(index_in_header, index)| {
                        let (data, rows) = block_bytes(frame, &order, pictures, index);
                        let block = exr::block::UncompressedBlock { index, data };
                        let chunk = block.compress_to_chunk(&meta.headers)?;
                        Ok(Block {
                            index_in_header,
                            chunk,
                            rows,
                            lines: index.pixel_size.height() as u64,
                        })
                    })
                    .collect()
            };
            let mut ready = Vec::new();
            for some in blocks.chunks(window) {
                let (made, written) = rayon::join(
                    || make(some),
                    || put(std::mem::take(&mut ready), chunks, streams, failed),
                );
                rows_written(written?);
                ready = made?;
            }
            rows_written(put(ready, chunks, streams, failed)?);
            Ok(())
        },
    )
}

/// A block of scan lines ready for the files: the EXR's chunk, compressed, and
/// the block's rows of every picture, picture after picture.
struct Block {
    index_in_header: usize,
    chunk: exr::block::chunk::Chunk,
    rows: Vec<u8>,
    /// How many scan lines it holds.
    lines: u64,
}

/// Write `blocks` (in order): their chunks to the EXR, and each picture's rows to
/// its PNG stream, the files in parallel. A PNG stream that fails leaves its
/// index and error in `failed`, and the write is aborted. Returns how many scan
/// lines were written.
fn put(
    blocks: Vec<Block>,
    chunks: &mut (impl ChunksWriter + Send),
    streams: &mut [PngStream],
    failed: &Mutex<Option<(usize, std::io::Error)>>,
) -> exr::error::Result<u64> {
    let lines = blocks.iter().map(|block| block.lines).sum();
    let (exr_chunks, rows): (Vec<_>, Vec<_>) = blocks
        .into_iter()
        .map(|block| ((block.index_in_header, block.chunk), block.rows))
        .unzip();
    let count = streams.len().max(1);
    let (exr, pngs) = rayon::join(
        || {
            (exr_chunks.into_iter())
                .try_for_each(|(index_in_header, chunk)| chunks.write_chunk(index_in_header, chunk))
        },
        || {
            streams
                .par_iter_mut()
                .enumerate()
                .try_for_each(|(k, stream)| {
                    for block in &rows {
                        let part = block.len() / count;
                        if let Err(e) = stream.write_all(&block[k * part..][..part]) {
                            *failed.lock().unwrap_or_else(|e| e.into_inner()) = Some((k, e));
                            return Err(exr::error::Error::Aborted);
                        }
                    }
                    Ok(())
                })
        },
    );
    exr.and(pngs).map(|()| lines)
}

/// The uncompressed bytes of one block of scan lines, and its rows of every
/// picture of `pictures` (picture after picture; none without). The EXR's bytes
/// are, for each line, for each channel in file order (`order`, indices into
/// [`exr_samples`]), the line's samples in native byte order (the crate's
/// compressor makes them little-endian).
fn block_bytes(
    frame: &Frame,
    order: &[usize],
    pictures: Pictures,
    index: BlockIndex,
) -> (Vec<u8>, Vec<u8>) {
    let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y());
    let (width, lines) = (index.pixel_size.width(), index.pixel_size.height());
    debug_assert!(x0 == 0 && width == frame.width as usize, "whole scan lines");
    // Each sample's four bytes pushed in turn (no zeros written first).
    let mut data: Vec<[u8; 4]> = Vec::with_capacity(width * lines * order.len());
    let picture_count = pictures.map_or(0, |(_, buffers)| buffers.len());
    let (picture_row, part) = (width * 3, width * 3 * lines);
    let mut rows = vec![0u8; part * picture_count];
    let (mut rays, mut terms) = (Vec::with_capacity(width), Vec::with_capacity(width));
    let mut colours = vec![[0.0; 3]; if pictures.is_some() { width } else { 0 }];
    for (line, row) in (y0..y0 + lines).enumerate() {
        let pixels = &frame.pixels[row * frame.width as usize + x0..][..width];
        let row = row as u32;
        rays.clear();
        terms.clear();
        frame.ray_buffers_row(row, x0 as u32..(x0 + width) as u32, &mut rays);
        terms.extend(pixels.iter().map(|p| frame.terms(p)));
        // Channel after channel, each a loop along the line of its own (the
        // channel's rule chosen once per line, not per sample).
        for &k in order {
            // The same numbers as `exr_sample` (tests/exr_readers.rs compares
            // every sample); the rest through it.
            match k {
                0..=2 => put_samples(&mut data, pixels.iter().map(|p| p.colour[k])),
                3..=5 => put_samples(&mut data, rays.iter().map(|r| r.0[k - 3])),
                6 => put_samples(&mut data, pixels.iter().map(|p| p.depth)),
                7..=9 => put_samples(&mut data, pixels.iter().map(|p| p.normal[k - 7])),
                10..=12 => put_samples(&mut data, rays.iter().map(|r| r.1[k - 10])),
                15..=23 => put_samples(
                    &mut data,
                    terms.iter().map(|t| t[(k - 15) / 3][(k - 15) % 3]),
                ),
                _ => put_samples(
                    &mut data,
                    (pixels.iter().zip(&rays).zip(&terms))
                        .map(|((p, r), t)| exr_sample(k, p, r, t)),
                ),
            }
        }
        if let Some((palette, buffers)) = pictures {
            let outs =
                (rows.chunks_exact_mut(part)).map(|p| &mut p[line * picture_row..][..picture_row]);
            palette.draw_rows(buffers, row, pixels, &rays, &terms, &mut colours, outs);
        }
    }
    (data.into_flattened(), rows)
}

/// Append one channel's samples of a line to `data`, as native float32 bytes.
/// (`samples` come from slices, so the vector knows their count up front and
/// writes them in a loop without checks, four at a time.)
#[inline(always)]
fn put_samples(data: &mut Vec<[u8; 4]>, samples: impl Iterator<Item = f32>) {
    data.extend(samples.map(f32::to_ne_bytes));
}
// ANCHOR_END: exr

/// The EXR file of a frame, as bytes, uncompressed (for tests; renders stream it
/// to the file).
pub fn exr_bytes(frame: &Frame) -> Result<Vec<u8>, Error> {
    exr_bytes_as(frame, ExrCompression::None)
}

/// The EXR file of a frame, as bytes, compressed as `compression` says.
pub fn exr_bytes_as(frame: &Frame, compression: ExrCompression) -> Result<Vec<u8>, Error> {
    let mut bytes = Cursor::new(Vec::new());
    exr_to(frame, &mut bytes, compression).map_err(|e| Error::Output {
        path: PathBuf::from(EXR_FILE),
        message: format!("cannot encode the EXR: {e}"),
    })?;
    Ok(bytes.into_inner())
}

/// Write the files of `frame`: the picture of each of `buffers` as a PNG file
/// to `temporaries[k]`, and the EXR file to the last of `temporaries`, in one
/// pass ([`stream_files`], which tells `rows_written` of each block written);
/// errors are reported against the final `paths`.
fn write_files(
    frame: &Frame,
    buffers: &[Buffer],
    png: PngEncoding,
    compression: ExrCompression,
    (temporaries, paths): (&[PathBuf], &[PathBuf]),
    rows_written: &(dyn Fn(u64) + Sync),
) -> Result<(), Error> {
    let fail = |k: usize, message: String| Error::Output {
        path: paths[k].clone(),
        message,
    };
    let mut streams = Vec::with_capacity(buffers.len());
    for (k, &buffer) in buffers.iter().enumerate() {
        let file = create_new(&temporaries[k]).map_err(|e| fail(k, e.to_string()))?;
        let stream = png_encoder(frame, buffer, png, BufWriter::new(file))
            .write_header()
            .and_then(|writer| writer.into_stream_writer_with_size(PNG_CHUNK))
            .map_err(|e| fail(k, e.to_string()))?;
        streams.push(stream);
    }
    let n = buffers.len();
    let file = create_new(&temporaries[n]).map_err(|e| fail(n, e.to_string()))?;
    let mut writer = BufWriter::new(file);
    let palette = Palette::new(frame, png, buffers);
    keep_freed_memory();
    let failed = Mutex::new(None);
    let written = stream_files(
        frame,
        &mut writer,
        compression,
        Some((&palette, buffers)),
        (&mut streams, &failed),
        rows_written,
    );
    if let Some((k, e)) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(fail(k, e.to_string()));
    }
    written.map_err(|e| fail(n, format!("cannot write the EXR: {e}")))?;
    writer.flush().map_err(|e| fail(n, e.to_string()))?;
    for (k, stream) in streams.into_iter().enumerate() {
        stream.finish().map_err(|e| fail(k, e.to_string()))?;
    }
    Ok(())
}

/// Have the memory allocator keep, for the next window, the memory of the
/// blocks [`stream_files`] frees window after window. glibc's `malloc` hands
/// freed memory back to the kernel once more than twice its "mmap threshold"
/// lies free at the top of a heap; the threshold starts at 128 KiB and rises to
/// the size of the largest block it mapped and then freed (up to 32 MiB). With
/// windows of a few MB, the kernel would map and zero fresh pages for every
/// window: at 1920 × 1080, 15,000 to 37,000 page faults more than the frame's own
/// 27,000, and about 0.1 s of system time (`/usr/bin/time -f %R` of such a
/// render, before and at commit 2a5f377). One 16 MiB block reserved and freed
/// (never touched, so never given pages) raises the threshold to 16 MiB first.
/// Allocators that keep freed memory anyway take it as a no-op.
fn keep_freed_memory() {
    drop(std::hint::black_box(Vec::<u8>::with_capacity(16 << 20)));
}

/// The most compressed bytes a PNG stream holds before it writes them out as
/// an `IDAT` chunk.
const PNG_CHUNK: usize = 256 << 10;

#[cfg(test)]
mod tests {
    use super::{fraction, to_byte};

    /// The reference rule: clip, scale, round half away from zero.
    fn rounded(v: f32) -> u8 {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }

    #[test]
    fn to_byte_rounds_as_f32_round_does() {
        // Every float from 0 to 1 (1,065,353,217 of them), in parallel, and what
        // lies outside.
        use rayon::prelude::*;
        let wrong = (0..=1f32.to_bits())
            .into_par_iter()
            .map(f32::from_bits)
            .find_first(|&v| to_byte(v) != rounded(v));
        assert_eq!(wrong, None, "to_byte differs from rounding");
        // Adding one half, as a first form did, is wrong once.
        let half = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        let v = 0.499_999_97 / 255.0;
        assert_eq!((half(v), to_byte(v), rounded(v)), (1, 0, 0));
        for v in [-0.0, -1.0, 1.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            assert_eq!(to_byte(v), rounded(v), "{v:e}");
        }
    }

    #[test]
    fn fraction_is_v_minus_its_floor() {
        // Every 257th float32 of either sign (16.7 million of them, across every
        // exponent), and the floats each side of whole numbers, of 2²³ and 2³¹.
        use rayon::prelude::*;
        let wrong = (0..=u32::MAX / 257)
            .into_par_iter()
            .map(|k| f32::from_bits(k * 257))
            .filter(|v| v.is_finite())
            .find_first(|&v| fraction(v).to_bits() != (v - v.floor()).to_bits());
        assert_eq!(wrong, None, "fraction differs from v - floor(v)");
        assert_eq!(fraction(-0.0).to_bits(), 0);
        for whole in [1.0f32, 2.0, 3.0, 1e6, 8_388_608.0, 2_147_483_648.0] {
            for v in [whole, -whole] {
                for v in [v.next_down(), v, v.next_up()] {
                    assert_eq!(fraction(v).to_bits(), (v - v.floor()).to_bits(), "{v:e}");
                }
            }
        }
        // Where v - floor(v) is not a number, the picture's byte is the same.
        for v in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            assert_eq!(to_byte(fraction(v)), to_byte(v - v.floor()), "{v:e}");
        }
    }
}
