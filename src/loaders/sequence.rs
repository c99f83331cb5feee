//! A series given as numbered files, one time point each: `--volume 'scan_*.nii.gz'` (a pattern in
//! the file name, quoted so that the shell leaves it), ordered by the last number in each name as
//! a folder's slices are.
use super::{bad, VolumeHints, MAX_TIME_POINTS};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Whether `path` names files by a pattern: no such file, and `*` or `?` in its file name.
pub fn is_pattern(path: &Path) -> bool {
    !path.exists() && path.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.contains(['*', '?']))
}

/// Whether `name` matches `pattern` (`*`: any run of characters, `?`: any one). On a mismatch it
/// resumes from the last `*` only, one character further: at most pattern × name steps. (A
/// recursive match backtracked through every `*`: `*a*a*a*a*a*a*a*a*b` against a name of 200
/// letters ran past 20 s.)
fn matches(pattern: &[char], name: &[char]) -> bool {
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        match pattern.get(p) {
            Some('*') => {
                star = Some((p, n));
                p += 1;
            }
            Some(&c) if c == '?' || c == name[n] => {
                p += 1;
                n += 1;
            }
            _ => match star {
                Some((sp, sn)) => {
                    star = Some((sp, sn + 1));
                    (p, n) = (sp + 1, sn + 1);
                }
                None => return false,
            },
        }
    }
    pattern[p..].iter().all(|&c| c == '*')
}

/// The files `pattern` matches in its folder, ordered by the number in each name.
pub fn files(pattern: &Path) -> Result<Vec<PathBuf>> {
    let what = pattern.display().to_string();
    let dir = pattern.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if dir.to_string_lossy().contains(['*', '?']) {
        return Err(Error::Unsupported(format!("{what}: a pattern matches file names in one folder, not folders")));
    }
    let pat: Vec<char> = pattern.file_name().map(|n| n.to_string_lossy().chars().collect()).unwrap_or_default();
    let io = |e| Error::Io { path: dir.display().to_string(), source: e };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let path = entry.map_err(io)?.path();
        let name: Vec<char> = path.file_name().map(|n| n.to_string_lossy().chars().collect()).unwrap_or_default();
        if path.is_file() && matches(&pat, &name) {
            let n = super::stacks::slice_number(&path).ok_or_else(|| {
                bad(&what, format!("{} has no number in its name to order the time points by", path.display()))
            })?;
            files.push((n, path));
        }
    }
    if files.is_empty() {
        return Err(bad(&what, "matches no file (a series of files: a pattern such as 'scan_*.nii.gz', quoted)"));
    }
    if files.len() as u64 > MAX_TIME_POINTS {
        return Err(bad(&what, format!("matches {} files; a series holds at most {MAX_TIME_POINTS}", files.len())));
    }
    files.sort();
    if let Some(w) = files.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(bad(&what, format!("{} and {} share number {}", w[0].1.display(), w[1].1.display(), w[0].0)));
    }
    Ok(files.into_iter().map(|(_, p)| p).collect())
}

/// When `path` is a pattern, the file of its time point `hints.time` (needed when it matches
/// several) and the hints to read that file with.
pub(super) fn member(path: &Path, hints: &VolumeHints) -> Result<Option<(PathBuf, VolumeHints)>> {
    if !is_pattern(path) {
        return Ok(None);
    }
    let files = files(path)?;
    // A pattern of one file is a series of one time point: --time 0 picks it.
    let time = hints.time.filter(|&t| !(files.len() == 1 && t == 0));
    let t = super::time_point(&path.display().to_string(), files.len() as u32, time)? as usize;
    Ok(Some((files[t].clone(), VolumeHints { time: None, ..hints.clone() })))
}
