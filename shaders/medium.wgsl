// The per-path medium stack. CPU twin: src/scene/medium.rs (same names), where the
// rule is documented.

// The dielectrics a ray is inside, outermost first: a refracted ray entering a
// dielectric pushes its index, one leaving pops; reflected rays keep the stack. Entries past `depth` are unused; deeper nesting than 4 keeps counting.
struct MediumStack {
    iors: vec4<f32>,
    depth: u32,
}

//#if REFRACTION
// The index of refraction `level` dielectrics deep (0 = air, index 1).
fn medium_ior_at(medium: MediumStack, level: u32) -> f32 {
    if level == 0u {
        return 1.0;
    }
    // Entry min(level, 4) - 1, picked with selects rather than a dynamic index.
    let i = min(level, 4u) - 1u;
    let v = medium.iors;
    return select(select(select(v.x, v.y, i == 1u), v.z, i == 2u), v.w, i == 3u);
}
//#endif

//#if REFRACTION
// The index on the outside of a dielectric surface: the current medium when entering,
// else the enclosing one.
fn medium_outside_ior(medium: MediumStack, entering: bool) -> f32 {
    if entering {
        return medium_ior_at(medium, medium.depth);
    }
    return medium_ior_at(medium, max(medium.depth, 1u) - 1u);
}
//#endif

//#if REFRACTION
// The stack of the refracted ray: `ior` pushed when entering, else popped.
fn medium_after_refraction(medium: MediumStack, entering: bool, ior: f32) -> MediumStack {
    var next = medium;
    if entering {
        // Entry `depth` (if below 4) becomes `ior`, set with a select rather than a
        // dynamic index.
        next.iors = select(next.iors, vec4<f32>(ior), vec4<u32>(0u, 1u, 2u, 3u) == vec4<u32>(next.depth));
        next.depth += 1u;
    } else if next.depth > 0u {
        next.depth -= 1u;
    }
    return next;
}
//#endif
