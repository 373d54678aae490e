//! Reading an OBJ file line by line ([`ObjReader`]) into an [`ObjFile`]: vertex data,
//! faces (cut into triangles by [`FaceCutter`]) collected into one group per object
//! (or group) name and material, `mtllib` and `usemtl` statements, with the limits on
//! what a file may hold checked as it grows.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::{DVec2, DVec3};

use super::contents::{FaceGroup, ObjFile};
use super::face::{Cut, FaceCutter};
use super::notes::Notes;
use super::syntax::{at, corner, finite, number, strip_comment, words};
use crate::scene::SceneError;
use crate::scene::import::mesh::memory_cap_message;
use crate::scene::import::{MAX_MODEL_TRIANGLES, MAX_MODEL_VERTICES};

/// The name of faces before any `o` or `g` (and of an `o` or `g` without a name), as
/// tobj names them.
const UNNAMED: &str = "unnamed_object";
/// Lines between two checks of the memory an OBJ file's arrays hold (and two progress
/// reports).
pub(super) const CHECK_EVERY_LINES: usize = 1 << 16;

/// The state of reading an OBJ file line by line.
pub(super) struct ObjReader<'p> {
    /// The file, named in messages.
    path: &'p Path,
    /// What has been read so far.
    file: ObjFile,
    /// The current `o`/`g` name.
    object: String,
    /// The current `usemtl` material (`None` before any, or after an empty one).
    material: Option<String>,
    /// The group of the current name and material, once a face has asked for it.
    current: Option<usize>,
    /// (name, material) → its group in `file.groups`.
    group_of: HashMap<(String, Option<String>), usize>,
    /// Material names already in `file.used_materials`.
    used: HashSet<String>,
    /// Triangles so far, against [`MAX_MODEL_TRIANGLES`].
    triangles: usize,
    /// Cuts faces into triangles.
    cutter: FaceCutter,
    /// Buffers reused from face to face: the face's corners, their positions, and its
    /// triangles (as indices into the corners).
    corners: Vec<[u32; 3]>,
    points: Vec<DVec3>,
    cut: Vec<[u32; 3]>,
    /// The most bytes the arrays may hold
    /// ([`ImportOptions::max_bytes`](crate::scene::import::ImportOptions::max_bytes) less
    /// the file).
    max_bytes: Option<u64>,
    /// Told the bytes read so far and the file's length.
    progress: Option<&'p (dyn Fn(u64, u64) + Sync)>,
}

impl<'p> ObjReader<'p> {
    /// A reader of the file at `path` that may hold at most `max_bytes` more (none:
    /// the fixed limits only) and reports its progress to `progress`.
    pub(super) fn new(
        path: &'p Path,
        max_bytes: Option<u64>,
        progress: Option<&'p (dyn Fn(u64, u64) + Sync)>,
    ) -> Self {
        Self {
            path,
            max_bytes,
            progress,
            file: ObjFile {
                positions: Vec::new(),
                colors: Vec::new(),
                texcoords: Vec::new(),
                normals: Vec::new(),
                groups: Vec::new(),
                libraries: Vec::new(),
                used_materials: Vec::new(),
                faces: 0,
                lines_and_points: 0,
                statements: 0,
                nonblank_lines: 0,
            },
            object: UNNAMED.to_string(),
            material: None,
            current: None,
            group_of: HashMap::new(),
            used: HashSet::new(),
            triangles: 0,
            cutter: FaceCutter::default(),
            corners: Vec::new(),
            points: Vec::new(),
            cut: Vec::new(),
        }
    }

    /// Reads every line of `text`, checking the memory its arrays hold and reporting
    /// progress every [`CHECK_EVERY_LINES`] lines.
    pub(super) fn read(mut self, text: &str, notes: &mut Notes) -> Result<ObjFile, SceneError> {
        let total = text.len() as u64;
        let (mut done, mut lines) = (0u64, 0);
        for line in text.lines() {
            lines += 1;
            self.statement(lines, strip_comment(line), notes)?;
            done += line.len() as u64 + 1;
            if lines % CHECK_EVERY_LINES == 0 {
                self.check_memory(lines)?;
                if let Some(progress) = self.progress {
                    progress(done.min(total), total);
                }
            }
        }
        self.check_memory(lines)?;
        if let Some(progress) = self.progress {
            progress(total, total);
        }
        Ok(self.file)
    }

    /// Refuses the file once the arrays read so far hold more than the cap allows
    /// (line `n` names where).
    fn check_memory(&self, n: usize) -> Result<(), SceneError> {
        let Some(max) = self.max_bytes else {
            return Ok(());
        };
        let file = &self.file;
        let groups: (u64, u64) = file.groups.iter().fold((0, 0), |(v, t), group| {
            (
                v + group.vertices.len() as u64,
                t + group.triangles.len() as u64,
            )
        });
        // A group's vertex is its index triple and its lookup entry (about 48 bytes
        // with the table's overhead); a triangle three indices.
        let held = file.positions.len() as u64 * 24
            + file.normals.len() as u64 * 24
            + file.texcoords.len() as u64 * 16
            + groups.0 * 48
            + groups.1 * 12;
        if held > max {
            return Err(SceneError::too_large(
                self.path,
                None,
                format!(
                    "by line {n}: {}",
                    memory_cap_message(held, max, "the arrays read so far")
                ),
            ));
        }
        Ok(())
    }

    /// Reads the statement on line `n` (its comment already cut off).
    fn statement(&mut self, n: usize, line: &str, notes: &mut Notes) -> Result<(), SceneError> {
        let words = words(line);
        let Some(&(column, keyword)) = words.first() else {
            return Ok(());
        };
        let values = &words[1..];
        // The rest of the line, for names that may hold spaces.
        let rest = || line.trim_start()[keyword.len()..].trim();
        self.file.nonblank_lines += 1;
        self.file.statements += 1;
        match keyword {
            "v" => self.position(n, column, values, notes)?,
            "vt" => self.texcoord(n, column, values, notes)?,
            "vn" => self.normal(n, column, values, notes)?,
            "f" => self.face(n, column, values, notes)?,
            "o" | "g" => {
                let name = rest();
                self.object = if name.is_empty() { UNNAMED } else { name }.to_string();
                self.current = None;
            }
            "usemtl" => {
                let name = rest();
                if name.is_empty() {
                    notes.empty_usemtl.note(|| n);
                    self.material = None;
                } else {
                    if self.used.insert(name.to_string()) {
                        self.file.used_materials.push((name.to_string(), n));
                    }
                    self.material = Some(name.to_string());
                }
                self.current = None;
            }
            "mtllib" => {
                let names = rest();
                if names.is_empty() {
                    notes.empty_mtllib.note(|| n);
                } else {
                    self.file.libraries.push((names.to_string(), n));
                }
            }
            // Smoothing groups: the normals come from `vn`.
            "s" => {}
            "l" | "p" => {
                self.file.lines_and_points += 1;
                notes.ignore(keyword, n);
            }
            _ => {
                self.file.statements -= 1;
                notes.ignore(keyword, n);
            }
        }
        Ok(())
    }

    /// Reads the position on line `n` (`v x y z`, with `w` or a colour `r g b`; `values`
    /// are its numbers) and its colour, if any.
    fn position(
        &mut self,
        n: usize,
        column: usize,
        values: &[(usize, &str)],
        notes: &mut Notes,
    ) -> Result<(), SceneError> {
        let path = self.path;
        if !matches!(values.len(), 3 | 4 | 6) {
            return Err(at(
                path,
                n,
                column,
                format!(
                    "`v` takes x y z (and optionally w, or r g b), got {} numbers",
                    values.len()
                ),
            ));
        }
        let mut position = [0.0; 3];
        for (what, (value, word)) in ["position x", "position y", "position z"]
            .iter()
            .zip(position.iter_mut().zip(values))
        {
            *value = finite(path, n, *word, what, notes)?;
        }
        // `w` weighs rational curves' control points; a polygon's vertex is
        // where x y z say (tinyobjloader and assimp ignore it too).
        if values.len() == 4 {
            number(path, n, values[3], "position w", notes)?;
        }
        let mut color = None;
        if values.len() == 6 {
            let mut rgb = [0.0; 3];
            for (value, word) in rgb.iter_mut().zip(&values[3..]) {
                *value = finite(path, n, *word, "vertex colour", notes)?;
            }
            color = Some(DVec3::from(rgb));
        }
        if self.file.positions.len() == MAX_MODEL_VERTICES {
            return Err(at(
                path,
                n,
                column,
                format!("more than {MAX_MODEL_VERTICES} vertex positions, more than accepted"),
            ));
        }
        self.file.positions.push(DVec3::from(position));
        // Vertices without a colour among coloured ones are white, as
        // tinyobjloader reads them.
        if color.is_some() || !self.file.colors.is_empty() {
            let vertex = self.file.positions.len() - 1;
            self.file.colors.resize(vertex, DVec3::ONE);
            self.file.colors.push(color.unwrap_or(DVec3::ONE));
        }
        Ok(())
    }

    /// Reads the texture coordinate on line `n` (`vt u (v (w))`; `values` are its
    /// numbers).
    fn texcoord(
        &mut self,
        n: usize,
        column: usize,
        values: &[(usize, &str)],
        notes: &mut Notes,
    ) -> Result<(), SceneError> {
        let path = self.path;
        if !(1..=3).contains(&values.len()) {
            return Err(at(
                path,
                n,
                column,
                format!("`vt` takes u (v (w)), got {} numbers", values.len()),
            ));
        }
        let u = number(path, n, values[0], "texture coordinate u", notes)?;
        // A missing v is 0 (the specification's default); w is for 3D textures.
        let v = match values.get(1) {
            Some(word) => number(path, n, *word, "texture coordinate v", notes)?,
            None => 0.0,
        };
        if let Some(word) = values.get(2) {
            number(path, n, *word, "texture coordinate w", notes)?;
        }
        self.file.texcoords.push(DVec2::new(u, 1.0 - v));
        Ok(())
    }

    /// Reads the normal on line `n` (`vn i j k`; `values` are its numbers).
    fn normal(
        &mut self,
        n: usize,
        column: usize,
        values: &[(usize, &str)],
        notes: &mut Notes,
    ) -> Result<(), SceneError> {
        let path = self.path;
        if values.len() != 3 {
            return Err(at(
                path,
                n,
                column,
                format!("`vn` takes i j k, got {} numbers", values.len()),
            ));
        }
        let mut normal = [0.0; 3];
        for (value, word) in normal.iter_mut().zip(values) {
            *value = number(path, n, *word, "normal", notes)?;
        }
        self.file.normals.push(DVec3::from(normal));
        Ok(())
    }
    /// Reads the face on line `n` (`values` are its corners) into the current group.
    fn face(
        &mut self,
        n: usize,
        column: usize,
        values: &[(usize, &str)],
        notes: &mut Notes,
    ) -> Result<(), SceneError> {
        self.file.faces += 1;
        let defined = [
            self.file.positions.len(),
            self.file.texcoords.len(),
            self.file.normals.len(),
        ];
        let mut dropped_normals = false;
        self.corners.clear();
        for (k, word) in values.iter().enumerate() {
            let corner = corner(self.path, n, k + 1, *word, defined, &mut dropped_normals)?;
            self.corners.push(corner);
        }
        if dropped_normals {
            notes.normals_without_vn.note(|| n);
        }
        if values.len() < 3 {
            notes.short_faces.note(|| n);
            return Ok(());
        }
        self.triangles += values.len() - 2;
        if self.triangles > MAX_MODEL_TRIANGLES {
            return Err(at(
                self.path,
                n,
                column,
                format!("more than {MAX_MODEL_TRIANGLES} triangles, more than accepted"),
            ));
        }
        self.points.clear();
        let positions = &self.file.positions;
        self.points
            .extend(self.corners.iter().map(|c| positions[c[0] as usize]));
        self.cut.clear();
        if self.cutter.cut(&self.points, &mut self.cut) == Cut::FanAfterEarsFailed {
            notes.fanned_faces.note(|| n);
        }
        let group = self.group();
        let group = &mut self.file.groups[group];
        for triangle in &self.cut {
            let vertices = triangle.map(|k| group.vertex(self.corners[k as usize]));
            group.triangles.push(vertices);
        }
        Ok(())
    }

    /// The group of the current name and material, made on first use.
    fn group(&mut self) -> usize {
        if let Some(group) = self.current {
            return group;
        }
        let key = (self.object.clone(), self.material.clone());
        let groups = &mut self.file.groups;
        let group = *self.group_of.entry(key).or_insert_with(|| {
            groups.push(FaceGroup {
                object: self.object.clone(),
                material: self.material.clone(),
                vertices: Vec::new(),
                lookup: HashMap::new(),
                triangles: Vec::new(),
            });
            groups.len() - 1
        });
        self.current = Some(group);
        group
    }
}
