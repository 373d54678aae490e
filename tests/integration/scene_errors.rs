//! Bad scene files: each must give a `SceneError` naming the file, the place and the
//! problem, never a panic.

use std::path::Path;

use gpu_render::scene::{
    LoadOptions, LoadProgress, SceneError, load_scene, load_scene_with, parse_scene,
};

const FILE: &str = "bad.toml";
const CAMERA: &str = "[camera]\neye = [0, 1, 5]\nlook_at = [0, 0.5, 0]\n";
const LAMBERT: &str = "[materials.grey]\ntype = \"lambert\"\nalbedo = 0.5\n";

/// Parses `text` expecting an error; checks that it names the file and contains every
/// one of `needles`; returns it.
fn error(text: &str, needles: &[&str]) -> SceneError {
    let err = match parse_scene(text, Path::new(FILE)) {
        Ok(_) => panic!("scene unexpectedly accepted:\n{text}"),
        Err(err) => err,
    };
    let shown = err.to_string();
    assert!(shown.starts_with(FILE), "no file name in {shown:?}");
    for needle in needles {
        assert!(shown.contains(needle), "{needle:?} missing from {shown:?}");
    }
    err
}

/// A scene with a camera, one material `grey` and `rest` appended.
fn scene(rest: &str) -> String {
    format!("{CAMERA}{LAMBERT}{rest}")
}

#[test]
fn syntax_error_has_line_and_column() {
    let err = error(
        "[camera]\neye = [0, 1, 5]\nlook_at = oops\n",
        &["bad.toml:3:11:"],
    );
    assert_eq!(err.location(), Some((3, 11)));
}

#[test]
fn unknown_top_level_table() {
    let err = error(&format!("{CAMERA}[lighting]\nx = 1\n"), &["lighting"]);
    assert_eq!(err.location().map(|l| l.0), Some(4));
}

#[test]
fn unknown_field_is_named_and_located() {
    let err = error(
        &scene("[[objects]]\ntype = \"sphere\"\ncentre = [0, 0, 0]\n"),
        &["unknown field `centre`", "objects"],
    );
    assert_eq!(err.location(), Some((9, 1)));
}

#[test]
fn field_of_another_type_is_rejected() {
    let err = error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nnormal = [0, 1, 0]\nmaterial = \"grey\"\n",
        ),
        &[
            "objects[0] (sphere)",
            "no field `normal`",
            "center, radius, material",
        ],
    );
    assert_eq!(err.location(), Some((7, 1)));
}

#[test]
fn wrong_type_names_the_field() {
    let err = error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\"\nmaterial = \"grey\"\n",
        ),
        &["`objects.radius`", "invalid type"],
    );
    assert_eq!(err.location(), Some((10, 10)));
}

#[test]
fn unknown_object_type() {
    let err = error(
        &scene("[[objects]]\ntype = \"cube\"\nmaterial = \"grey\"\n"),
        &[
            "objects[0]",
            "unknown object type `cube`",
            "sphere, plane, polygon, triangle",
        ],
    );
    assert_eq!(err.location(), Some((7, 1)));
}

#[test]
fn missing_required_field() {
    error(
        &scene("[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nmaterial = \"grey\"\n"),
        &["objects[0] (sphere)", "missing required field `radius`"],
    );
}

#[test]
fn missing_camera() {
    let err = error(LAMBERT, &["[camera]"]);
    assert_eq!(err.location(), None);
}

#[test]
fn undefined_material_lists_defined_ones() {
    let err = error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"gray\"\n",
        ),
        &[
            "objects[0] (sphere)",
            "material `gray` is not defined",
            "`grey`",
        ],
    );
    assert_eq!(err.location(), Some((7, 1)));
}

#[test]
fn nan_component_is_named() {
    let err = error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, nan, 0]\nradius = 1\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (sphere): center.y is NaN"],
    );
    assert_eq!(err.location(), Some((7, 1)));
}

#[test]
fn infinite_number_is_named() {
    error(
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = inf\n"),
        &["lights[0] (point): intensity is infinite"],
    );
}

#[test]
fn colour_out_of_range_names_the_channel() {
    error(
        &format!("{CAMERA}[materials.hot]\ntype = \"lambert\"\nalbedo = [0.5, 1.5, 0.5]\n"),
        &[
            "materials.hot (lambert)",
            "albedo.g must be in [0, 1], got 1.5",
        ],
    );
}

#[test]
fn blinn_phong_energy_names_the_channel() {
    error(
        &format!(
            "{CAMERA}[materials.shiny]\ntype = \"blinn_phong\"\ndiffuse = [0.5, 0.5, 0.8]\n\
             specular = 0.3\nshininess = 10\n"
        ),
        &["materials.shiny (blinn_phong)", "diffuse.b + specular.b"],
    );
}

#[test]
fn coat_ior_below_one() {
    error(
        &format!("{CAMERA}[materials.m]\ntype = \"lambert\"\nalbedo = 0.5\ncoat_ior = 0.5\n"),
        &["materials.m (lambert)", "coat_ior must be >= 1"],
    );
}

#[test]
fn eye_equals_look_at() {
    let err = error(
        "\n[camera]\neye = [1, 1, 1]\nlook_at = [1, 1, 1]\n",
        &["camera", "eye", "look_at"],
    );
    assert_eq!(err.location(), Some((2, 1)));
}

#[test]
fn zero_up() {
    error(
        &format!("{CAMERA}up = [0, 0, 0]\n"),
        &["camera: up is the zero vector"],
    );
}

#[test]
fn up_parallel_to_view() {
    error(
        "[camera]\neye = [0, 5, 0]\nlook_at = [0, 0, 0]\n",
        &["camera: up", "parallel to the view direction"],
    );
}

#[test]
fn fov_out_of_range() {
    error(
        &format!("{CAMERA}fov_y_degrees = 180\n"),
        &["camera", "fov_y_degrees must be in (0, 180)"],
    );
}

#[test]
fn width_zero() {
    let err = error(
        &format!("[render]\nwidth = 0\n{CAMERA}"),
        &["render: width must be between 1 and"],
    );
    assert_eq!(err.location(), Some((1, 1)));
}

#[test]
fn width_too_large() {
    error(
        &format!("[render]\nwidth = 100000\n{CAMERA}"),
        &["render: width", "got 100000"],
    );
}

#[test]
fn negative_width_is_a_type_error() {
    let err = error(
        &format!("[render]\nwidth = -1\n{CAMERA}"),
        &["`render.width`"],
    );
    assert_eq!(err.location(), Some((2, 9)));
}

#[test]
fn polygon_needs_three_vertices() {
    error(
        &scene(
            "[[objects]]\ntype = \"polygon\"\nvertices = [[0, 0, 0], [1, 0, 0]]\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (polygon)", "at least 3 vertices, got 2"],
    );
}

#[test]
fn non_planar_polygon_names_worst_vertex() {
    let err = error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"grey\"\n\
             [[objects]]\ntype = \"polygon\"\n\
             vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0.5], [0, 1, 0]]\nmaterial = \"grey\"\n",
        ),
        &["objects[1] (polygon)", "not planar", "vertex"],
    );
    assert_eq!(err.location(), Some((12, 1)));
}

#[test]
fn degenerate_polygon() {
    error(
        &scene(
            "[[objects]]\ntype = \"polygon\"\nvertices = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (polygon)", "degenerate"],
    );
}

#[test]
fn degenerate_triangle() {
    error(
        &scene(
            "[[objects]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (triangle)", "degenerate"],
    );
}

#[test]
fn triangle_needs_exactly_three_vertices() {
    error(
        &scene(
            "[[objects]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (triangle)", "exactly 3 vertices, got 4"],
    );
}

#[test]
fn sphere_radius_must_be_positive() {
    error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (sphere)", "radius must be > 0"],
    );
}

#[test]
fn plane_zero_normal() {
    error(
        &scene(
            "[[objects]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\nmaterial = \"grey\"\n",
        ),
        &["objects[0] (plane)", "normal is the zero vector"],
    );
}

#[test]
fn directional_zero_direction() {
    error(
        &format!(
            "{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = [0, 0, 0]\nirradiance = 1\n"
        ),
        &["lights[0] (directional)", "direction is the zero vector"],
    );
}

#[test]
fn too_many_objects() {
    let text = format!("objects = [{}]\n{}", "{},".repeat(1_000_001), scene(""));
    error(&text, &["1000001", "more than the 1000000 accepted"]);
}

#[test]
fn missing_file_names_the_os_error() {
    let dir = match tempfile::tempdir() {
        Ok(dir) => dir,
        Err(e) => panic!("{e}"),
    };
    let path = dir.path().join("absent.toml");
    let err = match load_scene(&path) {
        Ok(_) => panic!("loaded a missing file"),
        Err(err) => err,
    };
    let shown = err.to_string();
    assert!(
        shown.contains("absent.toml") && shown.contains("cannot read"),
        "{shown}"
    );
    assert!(shown.to_lowercase().contains("no such file"), "{shown}");
}

#[test]
fn directory_is_rejected() {
    let dir = match tempfile::tempdir() {
        Ok(dir) => dir,
        Err(e) => panic!("{e}"),
    };
    let err = match load_scene(dir.path()) {
        Ok(_) => panic!("loaded a directory"),
        Err(err) => err,
    };
    assert!(err.to_string().contains("directory"), "{err}");
}

#[test]
fn depth_at_the_integer_limit_is_an_error_not_an_overflow() {
    error(
        &format!("[render]\nmax_depth = 4294967295\n{CAMERA}"),
        &["render: max_depth must be at most"],
    );
}

#[test]
fn numbers_outside_32_bit_floats_are_rejected() {
    // The GPU would see 0 (a division by zero) or infinity where the CPU sees a number.
    error(
        &scene("[materials.glass]\ntype = \"dielectric\"\nior = 1e-300\n"),
        &["materials.glass", "ior", "too small for 32-bit floats"],
    );
    error(
        &scene(
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1e39\nmaterial = \"grey\"\n",
        ),
        &["objects[0]", "radius", "too large for 32-bit floats"],
    );
}

/// Asserts that `shown` is one line without control characters, of at most `most`
/// characters.
fn assert_one_short_line(shown: &str, most: usize) {
    assert!(!shown.contains(char::is_control), "{shown:?}");
    assert!(shown.chars().count() <= most, "{shown:?}");
}

#[test]
fn names_and_words_from_the_file_are_quoted_escaped_and_cut() {
    let long = "n".repeat(5_000);
    for (rest, needle) in [
        (
            "[materials.\"a\\u0000b\\nc\"]\ntype = \"lambert\"\nalbedo = 2\n".to_owned(),
            r"materials.a\0b\nc (lambert): albedo must be in [0, 1]",
        ),
        (
            "[materials.m]\ntype = \"lam\\u001b[31mbert\"\n".to_owned(),
            r"unknown material type `lam\u{1b}[31mbert`",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n\
             material = \"no\\u0000pe\"\n"
                .to_owned(),
            r"material `no\0pe` is not defined",
        ),
        (
            "[materials.grey2]\ntype = \"lambert\"\nalbedo = 0.5\n\"x\\u0000y\" = 1\n".to_owned(),
            r"unknown field `x\0y`",
        ),
        (
            format!("[[lights]]\ntype = \"{long}\"\n"),
            "unknown light type `nnnnnnnnnn",
        ),
        (
            format!("[materials.{long}]\ntype = \"lambert\"\nalbedo = 2\n"),
            "nnn… (lambert): albedo must be in [0, 1]",
        ),
        (
            format!("[materials.t]\ntype = \"lambert\"\nalbedo_texture = \"{long}\\u0007.png\"\n"),
            "albedo_texture `nnnnnnnnnn",
        ),
    ] {
        let err = error(&scene(&rest), &[needle]);
        assert_one_short_line(&err.to_string(), 700);
    }
}

#[test]
fn numbers_from_the_file_are_quoted_short() {
    for (rest, needle) in [
        (
            "[materials.m]\ntype = \"lambert\"\nalbedo = -3e38\n",
            "albedo must be in [0, 1], got -3e38",
        ),
        (
            "[materials.m]\ntype = \"blinn_phong\"\ndiffuse = 0.1\nspecular = 0.1\n\
             shininess = 3e38\n",
            "shininess must be at most 1e6, got 3e38",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -2.5e-30\n\
             material = \"grey\"\n",
            "radius must be > 0, got -2.5e-30",
        ),
    ] {
        let err = error(&scene(rest), &[needle]);
        assert_one_short_line(&err.to_string(), 200);
    }
}

#[test]
fn duplicate_key_names_the_key() {
    let err = error(
        "[camera]\neye = [0, 1, 5]\neye = [1, 2, 3]\nlook_at = [0, 0.5, 0]\n",
        &["duplicate key `eye`"],
    );
    assert_eq!(err.location(), Some((3, 1)));
    let err = error(
        &format!("{CAMERA}{LAMBERT}[materials.grey]\ntype = \"mirror\"\n"),
        &["duplicate table `[materials.grey]`"],
    );
    assert_eq!(err.location().map(|l| l.0), Some(7));
}

#[test]
fn recursion_limit_has_a_location() {
    // The TOML parser refuses a dotted key of more than 80 parts, without a place.
    let key = vec!["a"; 81].join(".");
    let err = error(
        &format!("{CAMERA}\n  {key} = 1\n"),
        &["recursion limit", "81 parts", "`a.a.a"],
    );
    assert_eq!(err.location(), Some((5, 3)));
    // Nesting too deep is located by the parser itself.
    let nested = format!("{CAMERA}x = {}{}\n", "[".repeat(100), "]".repeat(100));
    let err = error(&nested, &["recursion"]);
    assert_eq!(err.location().map(|l| l.0), Some(4));
}

#[test]
fn a_file_of_tiny_values_is_refused_before_parsing() {
    // 64 MiB of `[],` made the parser peak at 4.4 GB; it is refused by counting.
    let text = "[],".repeat(64 * 1024 * 1024 / 3 - 1);
    let err = error(
        &text,
        &[
            "44739240 values",
            "more than the 8000000 accepted",
            "in memory",
        ],
    );
    assert_eq!(err.location(), None);
    // Below the count a file of values is parsed (and fails for what it is).
    let small = format!("x = [{}]\n{CAMERA}", "[],".repeat(1000));
    error(&small, &["unknown field `x`"]);
}

#[cfg(unix)]
#[test]
fn a_fifo_as_scene_is_refused_without_blocking() {
    let dir = match tempfile::tempdir() {
        Ok(dir) => dir,
        Err(e) => panic!("{e}"),
    };
    let fifo = dir.path().join("scene.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
    // A hang would be the bug: the load runs on a thread that is given 30 s.
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(load_scene(&fifo).map(|_| ()).map_err(|e| e.to_string()));
    });
    let result = receive.recv_timeout(std::time::Duration::from_secs(30));
    let Ok(Err(shown)) = result else {
        panic!("load_scene did not refuse the FIFO in time: {result:?}");
    };
    assert!(
        shown.contains("scene.toml") && shown.contains("a FIFO, not a regular file"),
        "{shown}"
    );
}

#[test]
fn progress_is_reported_through_the_hook() {
    let dir = match tempfile::tempdir() {
        Ok(dir) => dir,
        Err(e) => panic!("{e}"),
    };
    let path = dir.path().join("scene.toml");
    let sphere =
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"grey\"\n";
    let text = scene(&sphere.repeat(10));
    if let Err(e) = std::fs::write(&path, &text) {
        panic!("{e}");
    }
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |p: LoadProgress| seen.lock().unwrap_or_else(|e| e.into_inner()).push(p);
    let options = LoadOptions {
        progress: Some(&record),
        ..LoadOptions::default()
    };
    if let Err(e) = load_scene_with(&path, &options) {
        panic!("{e}");
    }
    let seen = seen.into_inner().unwrap_or_else(|e| e.into_inner());
    let bytes = text.len() as u64;
    assert_eq!(seen[0], LoadProgress::Reading { bytes });
    assert_eq!(seen[1], LoadProgress::Parsing { bytes });
    // One material and ten objects.
    assert_eq!(seen.len(), 2 + 11);
    assert_eq!(
        seen.last(),
        Some(&LoadProgress::Checking {
            done: 11,
            total: 11
        })
    );
}

/// A Radiance HDR file whose first line is `#?RGBE`, as Mitsuba writes it, with the
/// texels `(x, y) → [x/4, y/2, 0.5]`.
fn write_rgbe_hdr(path: &Path) {
    let image = image::Rgb32FImage::from_fn(4, 2, |x, y| {
        image::Rgb([x as f32 / 4.0, y as f32 / 2.0, 0.5])
    });
    image::DynamicImage::ImageRgb32F(image)
        .save(path)
        .expect("write hdr");
    let bytes = std::fs::read(path).expect("read hdr");
    let rest = bytes
        .strip_prefix(b"#?RADIANCE\n".as_slice())
        .expect("the encoder's first line");
    std::fs::write(path, [b"#?RGBE\n".as_slice(), rest].concat()).expect("rewrite hdr");
}

#[test]
fn an_hdr_file_with_the_rgbe_header_loads_as_a_texture_and_an_environment_map() {
    let dir = tempfile::tempdir().expect("tempdir");
    write_rgbe_hdr(&dir.path().join("sky.hdr"));
    let path = dir.path().join("scene.toml");
    let text = format!(
        "{CAMERA}[environment]\nmap = \"sky.hdr\"\n\
         [materials.wall]\ntype = \"lambert\"\nalbedo_texture = \"sky.hdr\"\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"wall\"\n"
    );
    std::fs::write(&path, text).expect("write scene");
    let scene = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let map = scene.environment.map.as_ref().expect("an environment map");
    let texture = scene.images.first().expect("a texture");
    for image in [&map.image, texture] {
        assert_eq!((image.width, image.height), (4, 2));
        // RGBE holds these values exactly.
        assert_eq!(image.texel(3, 1), [0.75, 0.5, 0.5, 1.0]);
    }
}

/// One fill rule for polygons: the even-odd crossing test. A self-crossing outline of
/// at most 32 vertices is filled by it; where the tracers would fill it otherwise (a
/// larger outline is triangulated, an emitter's area is sampled by its triangles) it is
/// refused with the crossing edges named, whatever its vertex count.
#[test]
fn self_crossing_polygons_are_refused_where_they_would_not_fill_by_the_even_odd_rule() {
    let polygon = |material: &str, vertices: &[(f64, f64)]| {
        let list: Vec<String> = vertices
            .iter()
            .map(|(x, y)| format!("[{x}, {y}, 0]"))
            .collect();
        format!(
            "[materials.lamp]\ntype = \"emissive\"\nradiance = 1\n\
             [[objects]]\ntype = \"polygon\"\nmaterial = \"{material}\"\nvertices = [{}]\n",
            list.join(", ")
        )
    };
    // Lobes of unequal size, so that the outline encloses some signed area.
    let bow_tie = [(0.0, 0.0), (3.0, 2.0), (3.0, 0.0), (0.0, 1.0)];
    // Small and not emitting: accepted, filled by the even-odd rule.
    parse_scene(&scene(&polygon("grey", &bow_tie)), Path::new(FILE)).expect("accepted");
    // Emitting: refused, naming the edges that cross.
    error(
        &scene(&polygon("lamp", &bow_tie)),
        &[
            "objects[0] (polygon)",
            "crosses itself",
            "edge 0",
            "edge 2",
            "emitting",
        ],
    );
    // 40 corners whose outline crosses (a zigzag closed back over itself).
    let mut zigzag: Vec<(f64, f64)> = (0..39)
        .map(|i| (f64::from(i), if i % 2 == 0 { 0.0 } else { 1.0 }))
        .collect();
    zigzag.push((19.0, 2.0));
    error(
        &scene(&polygon("grey", &zigzag)),
        &["crosses itself", "more than 32 vertices", "triangulated"],
    );
    // A simple outline of 40 corners: accepted.
    let comb: Vec<(f64, f64)> = (0..40)
        .map(|i| {
            let a = f64::from(i) / 40.0 * std::f64::consts::TAU;
            let r = if i % 2 == 0 { 2.0 } else { 1.0 };
            (r * a.cos(), r * a.sin())
        })
        .collect();
    parse_scene(&scene(&polygon("grey", &comb)), Path::new(FILE)).expect("accepted");
}

/// Radiance and light strengths above 1e30 are refused where they are written: the GPU
/// sums samples in f32, and a 1e38 environment at 4 samples per pixel overflowed (issue
/// 26). 1e30 itself is accepted.
#[test]
fn radiance_that_the_gpu_cannot_sum_is_refused() {
    for (text, needles) in [
        (
            scene("[materials.lamp]\ntype = \"emissive\"\nradiance = 2e30\n"),
            &["materials.lamp", "at most 1e30"][..],
        ),
        (
            format!("{CAMERA}[environment]\nbackground = [1, 3e38, 1]\n"),
            &["environment", "at most 1e30"][..],
        ),
        (
            format!(
                "{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = 1e20\ncolor = [1e15, 1, 1]\n"
            ),
            &["lights[0]", "intensity times color", "1e35"][..],
        ),
        (
            format!(
                "{CAMERA}[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = 3e38\n"
            ),
            &["irradiance times color", "above the 1e30"][..],
        ),
    ] {
        error(&text, needles);
    }
    let accepted = format!(
        "{CAMERA}[environment]\nbackground = 1e30\n[materials.lamp]\ntype = \"emissive\"\nradiance = 1e30\n\
         [[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = 1e30\n"
    );
    parse_scene(&accepted, Path::new(FILE)).expect("1e30 is accepted");
}

/// An embedder can tell the kinds of scene errors apart and reach the error beneath:
/// a missing file is `Read` with the OS's error as its source, a TOML mistake `Syntax`
/// at its place, a value out of range `Invalid`, a missing texture `Image` with the
/// image's error as its source, glTF 1.0 `Unsupported`, and a model over the memory
/// cap `TooLarge`; each shows the same located text as before.
#[test]
fn scene_errors_say_their_kind_and_keep_their_source() {
    use gpu_render::low_level::input::InputError;
    use gpu_render::scene::ImageError;
    use gpu_render::scene::import::{ImportOptions, import_obj_with, parse_gltf};
    use std::error::Error as _;

    let missing = load_scene(Path::new("no/such/scene.toml")).expect_err("missing");
    match &missing {
        SceneError::Read { source, .. } => {
            assert!(
                matches!(&**source, InputError::Io(e) if e.kind() == std::io::ErrorKind::NotFound)
            );
        }
        other => panic!("a missing scene file is a Read error, got {other:?}"),
    }
    assert!(
        missing.source().is_some(),
        "the I/O error is kept as the source"
    );
    assert_eq!(missing.path(), Path::new("no/such/scene.toml"));

    let syntax = error(
        "[camera]\neye = [0, 1, 5]\nlook_at = oops\n",
        &["bad.toml:3:11:"],
    );
    assert!(
        matches!(
            syntax,
            SceneError::Syntax {
                location: Some((3, 11)),
                ..
            }
        ),
        "{syntax:?}"
    );

    let invalid = error(&scene("[render]\nwidth = 0\n"), &["width"]);
    assert!(matches!(invalid, SceneError::Invalid { .. }), "{invalid:?}");

    let dir = tempfile::tempdir().expect("tempdir");
    let scene_path = dir.path().join("textured.toml");
    std::fs::write(
        &scene_path,
        scene("[materials.wood]\ntype = \"lambert\"\nalbedo_texture = \"missing.png\"\n"),
    )
    .expect("write");
    let image = load_scene(&scene_path).expect_err("missing texture");
    match &image {
        SceneError::Image {
            source, location, ..
        } => {
            assert!(matches!(source, ImageError::Read(_)), "{source:?}");
            assert!(location.is_some(), "the material is located");
        }
        other => panic!("a missing texture is an Image error, got {other:?}"),
    }
    assert!(image.to_string().contains("missing.png"), "{image}");
    assert!(image.source().is_some());

    let gltf1 = parse_gltf(
        br#"{"asset": {"version": "1.0"}, "meshes": {"m": {}}}"#,
        Path::new("old.gltf"),
    )
    .expect_err("glTF 1.0");
    assert!(matches!(gltf1, SceneError::Unsupported { .. }), "{gltf1:?}");

    let obj = dir.path().join("big.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".repeat(1000)).expect("write");
    let capped = import_obj_with(
        &obj,
        &ImportOptions {
            max_bytes: Some(1000),
            progress: None,
        },
    )
    .expect_err("over the cap");
    assert!(matches!(capped, SceneError::TooLarge { .. }), "{capped:?}");
    assert!(capped.to_string().contains("--max-memory"), "{capped}");
}
