//! The sections of an MSH 4.1 file, read as the format defines them (Gmsh reference manual,
//! "MSH file format", version 4.1): `$MeshFormat`, `$PhysicalNames`, `$Entities`,
//! `$PartitionedEntities`, `$Nodes`, `$Elements` and `$GhostElements` are read; every other
//! section (`$Periodic`, `$Parametrizations`, `$NodeData`, `$ElementData`, `$ElementNodeData`,
//! `$InterpolationScheme`, comments, a program's own) is passed over to its end marker, as
//! Gmsh does with the sections it does not know.

use super::cursor::{Cursor, Encoding, Result};
use std::collections::HashMap;

/// One block of `$Nodes`: the nodes of one entity.
pub(super) struct NodeBlock {
    pub(super) tags: Vec<u64>,
    pub(super) coords: Vec<[f64; 3]>,
}

/// One block of `$Elements`: elements of one type on one entity, `per` node tags each.
pub(super) struct ElementBlock {
    pub(super) dim: i32,
    pub(super) entity: i32,
    pub(super) element_type: i32,
    pub(super) per: usize,
    /// Element tags.
    pub(super) tags: Vec<u64>,
    /// Node tags, `per` per element.
    pub(super) nodes: Vec<u64>,
}

/// What the reader takes from a file.
#[derive(Default)]
pub(super) struct File {
    /// `(dimension, physical tag) -> name`.
    pub(super) names: HashMap<(i32, i32), String>,
    /// `(dimension, entity tag) -> physical tags`, of the model's entities and of a
    /// partitioned file's partition entities.
    pub(super) physical: HashMap<(i32, i32), Vec<i32>>,
    pub(super) nodes: Vec<NodeBlock>,
    pub(super) elements: Vec<ElementBlock>,
    /// The partitions of a partitioned file (`$PartitionedEntities`), 0 where it is not.
    pub(super) partitions: u64,
    /// `(dimension, entity tag) -> partitions` of a partitioned file's partition entities.
    pub(super) entity_partitions: HashMap<(i32, i32), Vec<i32>>,
    /// The ghost entities (the entities that hold another partition's cells) and the
    /// partition that holds them.
    pub(super) ghost_entities: HashMap<i32, i32>,
    /// `$GhostElements`: each ghost element's tag and the partition that owns it.
    pub(super) ghost_owner: HashMap<u64, i32>,
    seen: Vec<&'static str>,
}

/// Nodes of the element types of Gmsh (its `ElementType` numbers): the first- and
/// higher-order lines, triangles, quadrilaterals, tetrahedra, hexahedra, prisms, pyramids and
/// the point. A type not listed here is refused by name.
pub(super) fn nodes_of_type(t: i32) -> Option<usize> {
    Some(match t {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        22 => 12,
        23 | 24 => 15,
        25 => 21,
        26 => 4,
        27 => 5,
        28 => 6,
        29 => 20,
        30 => 35,
        31 => 56,
        92 => 64,
        93 => 125,
        _ => return None,
    })
}

/// The name of an element type, for messages.
pub(super) fn type_name(t: i32) -> String {
    match t {
        1 => "2-node line".into(),
        2 => "3-node triangle".into(),
        3 => "4-node quadrilateral".into(),
        4 => "4-node tetrahedron".into(),
        5 => "8-node hexahedron".into(),
        6 => "6-node prism".into(),
        7 => "5-node pyramid".into(),
        8 => "3-node (second-order) line".into(),
        9 => "6-node (second-order) triangle".into(),
        10 => "9-node (second-order) quadrilateral".into(),
        11 => "10-node (second-order) tetrahedron".into(),
        15 => "1-node point".into(),
        16 => "8-node (second-order) quadrilateral".into(),
        t => match nodes_of_type(t) {
            Some(n) => format!("element type {t} ({n} nodes)"),
            None => format!("element type {t}"),
        },
    }
}

/// Reads the sections of `bytes`.
pub(super) fn read(bytes: &[u8]) -> Result<File> {
    let mut c = Cursor::new(bytes);
    if c.at_end() {
        return Err("not a Gmsh file: the file is empty".into());
    }
    let first = c.token("`$MeshFormat`").unwrap_or("");
    if first != "$MeshFormat" {
        return Err("not a Gmsh file: it does not start with `$MeshFormat`".into());
    }
    mesh_format(&mut c)?;
    let mut file = File::default();
    while !c.at_end() {
        let marker = c.token("a section")?;
        let Some(name) = marker.strip_prefix('$') else {
            let shown: String = marker.chars().take(40).collect();
            return Err(format!("`{shown}` where a section (`$Name`) should begin"));
        };
        let section: &'static str = match name {
            "PhysicalNames" => "`$PhysicalNames`",
            "Entities" => "`$Entities`",
            "PartitionedEntities" => "`$PartitionedEntities`",
            "Nodes" => "`$Nodes`",
            "Elements" => "`$Elements`",
            "GhostElements" => "`$GhostElements`",
            "MeshFormat" => return Err("a second `$MeshFormat`: two files joined into one?".into()),
            _ => {
                // a section this reader does not use, passed over as Gmsh does
                c.section = "a section";
                let end = format!("$End{name}");
                c.skip_past(&end).map_err(|_| format!("`${name}` has no `{end}`"))?;
                continue;
            }
        };
        if file.seen.contains(&section) {
            return Err(format!(
                "a second {section} section: the file holds two meshes (a post-processing view saved with its mesh, appended to the mesh file?)"
            ));
        }
        file.seen.push(section);
        c.section = section;
        if c.encoding != Encoding::Ascii && name != "PhysicalNames" {
            c.end_of_line()?; // binary data start on the next byte
        }
        match name {
            "PhysicalNames" => physical_names(&mut c, &mut file)?,
            "Entities" => entities(&mut c, &mut file)?,
            "PartitionedEntities" => partitioned_entities(&mut c, &mut file)?,
            "Nodes" => nodes(&mut c, &mut file)?,
            "GhostElements" => ghost_elements(&mut c, &mut file)?,
            _ => elements(&mut c, &mut file)?,
        }
        c.expect_end(name)?;
    }
    if !file.seen.contains(&"`$Nodes`") {
        return Err("the file has no `$Nodes` section".into());
    }
    if !file.seen.contains(&"`$Elements`") {
        return Err("the file has no `$Elements` section".into());
    }
    Ok(file)
}

/// The `$MeshFormat` section: version 4.1, file type 0 (ASCII) or 1 (binary, with the int 1
/// that shows the byte order), a data size (`sizeof(size_t)`) of 8 or 4.
fn mesh_format(c: &mut Cursor<'_>) -> Result<()> {
    c.section = "`$MeshFormat`";
    let version = c.token("the version")?;
    if version.parse::<f64>().ok() != Some(4.1) {
        return Err(format!(
            "MSH version `{version}` is not supported (only 4.1; Gmsh: -format msh41, or Mesh.MshFileVersion = 4.1)"
        ));
    }
    let kind = c.token("the file type")?;
    let size = c.token("the data size")?;
    let size_t = match size.parse::<u32>() {
        Ok(8) => 8,
        Ok(4) => 4,
        _ => return Err(format!("data size `{size}` in `$MeshFormat` is neither 8 nor 4")),
    };
    match kind.parse::<u32>() {
        Ok(0) => {}
        Ok(1) => {
            c.end_of_line()?;
            let one = c.take(4, "the byte-order int")?;
            let little = if one == 1i32.to_le_bytes() {
                true
            } else if one == 1i32.to_be_bytes() {
                false
            } else {
                return Err(
                    "the binary `$MeshFormat` lacks the int 1 that gives the byte order (a binary file saved as text, with its line ends changed?)"
                        .into(),
                );
            };
            c.encoding = Encoding::Binary { little, size_t };
        }
        _ => {
            return Err(format!(
                "file type `{kind}` in `$MeshFormat` is neither 0 (ASCII) nor 1 (binary)"
            ))
        }
    }
    c.expect_end("MeshFormat")
}

/// `$PhysicalNames` (text in both encodings): a count, then `dimension tag "name"` per line.
fn physical_names(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    let saved = c.encoding;
    c.encoding = Encoding::Ascii;
    let count = c.size("the count of names")?;
    c.line()?;
    let mut read = 0u64;
    while read < count {
        let raw = c.line()?;
        let line = raw.trim();
        if line.is_empty() {
            if c.remaining() == 0 {
                break;
            }
            continue;
        }
        let bad = || format!("`$PhysicalNames` line `{line}` is not `dimension tag \"name\"`");
        let (d, rest) = split_token(line);
        let (tag, rest) = split_token(rest);
        let d: i32 = d.parse().map_err(|_| bad())?;
        let tag: i32 = tag.parse().map_err(|_| bad())?;
        let name = rest.trim();
        let name = match name.strip_prefix('"') {
            Some(inner) => inner.strip_suffix('"').ok_or_else(bad)?,
            None if !name.is_empty() => name,
            None => return Err(bad()),
        };
        if file.names.insert((d, tag), name.to_string()).is_some() {
            return Err(format!(
                "`$PhysicalNames` names the group of dimension {d} and tag {tag} twice"
            ));
        }
        read += 1;
    }
    if read != count {
        return Err(format!("`$PhysicalNames` announces {count} names and holds {read}"));
    }
    c.encoding = saved;
    Ok(())
}

/// The first whitespace-separated token of `s` and the rest after it.
fn split_token(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    match s.find(|ch: char| ch.is_ascii_whitespace()) {
        Some(i) => (&s[..i], &s[i..]),
        None => (s, ""),
    }
}

/// The physical tags of an entity (`numPhysicalTags` then the tags).
fn physical_tags(c: &mut Cursor<'_>) -> Result<Vec<i32>> {
    let n = c.size("a count of physical tags")?;
    let mut tags = Vec::with_capacity(c.capacity(n, c.least_bytes()));
    for _ in 0..n {
        tags.push(c.int("a physical tag")?);
    }
    Ok(tags)
}

/// Skips an entity's bounding entities (`numBounding` then their signed tags).
fn skip_bounding(c: &mut Cursor<'_>) -> Result<()> {
    let n = c.size("a count of bounding entities")?;
    for _ in 0..n {
        c.int("a bounding entity")?;
    }
    Ok(())
}

/// The four entity counts (points, curves, surfaces, volumes).
fn entity_counts(c: &mut Cursor<'_>) -> Result<[u64; 4]> {
    Ok([
        c.size("the count of points")?,
        c.size("the count of curves")?,
        c.size("the count of surfaces")?,
        c.size("the count of volumes")?,
    ])
}

/// `$Entities`: each entity's physical tags.
fn entities(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    let counts = entity_counts(c)?;
    for (d, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            let tag = c.int("an entity tag")?;
            // a point's coordinates, or the bounding box of a curve, surface or volume
            c.skip_floats(if d == 0 { 3 } else { 6 }, "an entity's coordinates")?;
            let phys = physical_tags(c)?;
            if d > 0 {
                skip_bounding(c)?;
            }
            file.physical.entry((d as i32, tag)).or_insert(phys);
        }
    }
    Ok(())
}

/// `$PartitionedEntities`: the partition entities' physical tags (a partitioned file's node and
/// element blocks are on them).
fn partitioned_entities(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    file.partitions = c.size("the count of partitions")?;
    let ghosts = c.size("the count of ghost entities")?;
    for _ in 0..ghosts {
        let tag = c.int("a ghost entity tag")?;
        let partition = c.int("a ghost entity's partition")?;
        file.ghost_entities.insert(tag, partition);
    }
    let counts = entity_counts(c)?;
    for (d, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            let tag = c.int("an entity tag")?;
            c.int("a parent's dimension")?;
            c.int("a parent's tag")?;
            let parts = c.size("a count of partitions")?;
            let mut partitions = Vec::with_capacity(c.capacity(parts, c.least_bytes()));
            for _ in 0..parts {
                partitions.push(c.int("a partition tag")?);
            }
            file.entity_partitions.insert((d as i32, tag), partitions);
            c.skip_floats(if d == 0 { 3 } else { 6 }, "an entity's coordinates")?;
            let phys = physical_tags(c)?;
            if d > 0 {
                skip_bounding(c)?;
            }
            file.physical.insert((d as i32, tag), phys);
        }
    }
    Ok(())
}

/// `$Nodes`: blocks of tags then coordinates (and parametric coordinates, skipped).
fn nodes(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    let blocks = c.size("the count of blocks")?;
    let total = c.size("the count of nodes")?;
    c.size("the smallest node tag")?;
    c.size("the largest node tag")?;
    let mut held = 0u64;
    for _ in 0..blocks {
        let dim = c.int("a block's dimension")?;
        c.int("a block's entity")?;
        let parametric = c.int("a block's parametric flag")?;
        if !(0..=3).contains(&dim) || !(0..=1).contains(&parametric) {
            return Err(format!(
                "`$Nodes`: a block of dimension {dim} with parametric flag {parametric} (0..3 and 0 or 1)"
            ));
        }
        let n = c.size("a block's node count")?;
        let mut tags = Vec::with_capacity(c.capacity(n, c.least_bytes()));
        for _ in 0..n {
            tags.push(c.size("a node tag")?);
        }
        // x y z, then u (a curve's), u v (a surface's) or u v w (a volume's) where parametric
        let extra = if parametric == 1 { dim as usize } else { 0 };
        let mut coords = Vec::with_capacity(tags.len());
        for _ in 0..tags.len() {
            let x = [
                c.float("a coordinate")?,
                c.float("a coordinate")?,
                c.float("a coordinate")?,
            ];
            c.skip_floats(extra, "a parametric coordinate")?;
            coords.push(x);
        }
        held += n;
        file.nodes.push(NodeBlock { tags, coords });
    }
    if held != total {
        return Err(format!(
            "the $Nodes header declares {total} nodes but its blocks hold {held}"
        ));
    }
    Ok(())
}

/// `$GhostElements`: each ghost element's tag, the partition that owns it, and the partitions
/// that hold it as a ghost (not kept).
fn ghost_elements(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    let n = c.size("the count of ghost elements")?;
    file.ghost_owner.reserve(c.capacity(n, 3 * c.least_bytes()));
    for _ in 0..n {
        let tag = c.size("a ghost element's tag")?;
        let owner = c.int("a ghost element's partition")?;
        let holders = c.size("a ghost element's count of ghost partitions")?;
        for _ in 0..holders {
            c.int("a ghost partition")?;
        }
        if file.ghost_owner.insert(tag, owner).is_some() {
            return Err(format!("`$GhostElements` lists element {tag} twice"));
        }
    }
    Ok(())
}

/// `$Elements`: blocks of one type on one entity, each element its tag and its node tags.
fn elements(c: &mut Cursor<'_>, file: &mut File) -> Result<()> {
    let blocks = c.size("the count of blocks")?;
    let total = c.size("the count of elements")?;
    c.size("the smallest element tag")?;
    c.size("the largest element tag")?;
    let mut held = 0u64;
    for _ in 0..blocks {
        let dim = c.int("a block's dimension")?;
        let entity = c.int("a block's entity")?;
        let element_type = c.int("a block's element type")?;
        let n = c.size("a block's element count")?;
        let per = nodes_of_type(element_type).ok_or_else(|| {
            format!("`$Elements`: element type {element_type} is not a Gmsh element type this reader knows")
        })?;
        let mut tags = Vec::with_capacity(c.capacity(n, c.least_bytes() * (1 + per)));
        let mut nodes = Vec::with_capacity(tags.capacity() * per);
        for _ in 0..n {
            tags.push(c.size("an element tag")?);
            for _ in 0..per {
                nodes.push(c.size("an element's node tag")?);
            }
        }
        held += n;
        file.elements.push(ElementBlock {
            dim,
            entity,
            element_type,
            per,
            tags,
            nodes,
        });
    }
    if held != total {
        return Err(format!(
            "the $Elements header declares {total} elements but its blocks hold {held}"
        ));
    }
    Ok(())
}
