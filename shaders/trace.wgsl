// The Whitted tracer: one invocation per pixel, each sample traced iteratively with an
// explicit bounce stack (WGSL has no recursion). CPU twin: src/cpu/trace.rs.
// STACK_SIZE is prepended by the host (src/gpu/shaders.rs) when it composes the module.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read> planes: array<Plane>;
@group(0) @binding(3) var<storage, read> polygons: array<Polygon>;
@group(0) @binding(4) var<storage, read> polygon_vertices: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(6) var<storage, read> materials: array<Material>;
@group(0) @binding(7) var<storage, read> lights: array<Light>;
@group(0) @binding(8) var linear_output: texture_storage_2d<rgba32float, write>;
// One counter per image row: the rays each pixel of the row traced.
@group(0) @binding(9) var<storage, read_write> ray_counts: array<atomic<u32>>;
// Running radiance sums of the dispatched rows (row - row_offset, column), carried
// from one sample's dispatch to the next.
@group(0) @binding(10) var<storage, read_write> accumulation: array<vec4<f32>>;

// Rays traced by this invocation (camera, shadow and secondary).
var<private> rays_traced: u32;

// Squared point-light distances below the smallest normal f32 (2^-126) contribute
// nothing: I / r² would be infinite or NaN. Twin of MIN_LIGHT_DISTANCE_SQUARED.
const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1.17549435e-38;

// The dielectrics a ray is inside, outermost first (the per-path medium stack; the
// rule is documented on the CPU twin, MediumStack in src/cpu/trace.rs): a refracted
// ray entering a dielectric pushes its index, one leaving pops; reflected rays keep
// the stack. Entries past `depth` are unused; deeper nesting than 4 keeps counting.
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
    return medium.iors[min(level, 4u) - 1u];
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
        if next.depth < 4u {
            next.iors[next.depth] = ior;
        }
        next.depth += 1u;
    } else if next.depth > 0u {
        next.depth -= 1u;
    }
    return next;
}
//#endif

// Whether every component is finite, read from the exponent bits so that no
// fast-math assumption of the shader compiler can fold the test away. The final guard
// of trace_radiance; twin of finite_radiance.
fn finite_radiance(c: vec3<f32>) -> bool {
    let exponent = bitcast<vec3<u32>>(c) & vec3<u32>(0x7f800000u);
    return all(exponent != vec3<u32>(0x7f800000u));
}

struct StackEntry {
    ray: Ray,
    // Product of the weights of the bounces that led here.
    weight: vec3<f32>,
    // Bounces since the primary ray.
    depth: u32,
    // The dielectrics the ray travels inside.
    medium: MediumStack,
}

struct ShadedHit {
    // Emitted plus directly lit (and ambient) radiance towards the eye.
    radiance: vec3<f32>,
    reflect_weight: vec3<f32>,
    reflected: Ray,
    transmit_weight: vec3<f32>,
    transmitted: Ray,
    transmitted_medium: MediumStack,
}

// Reflected radiance due to one light, f(wi, wo)·E·cos θi, if the shadow ray from
// `origin` to the light is unblocked. Counts the shadow ray it traces.
fn direct_light(light: Light, material: Material, origin: vec3<f32>, n: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    var wi: vec3<f32>;
    var distance: f32;
    var irradiance: vec3<f32>;
    if light.kind == LIGHT_POINT {
        let to_light = light.position_or_direction - origin;
        let distance_squared = dot(to_light, to_light);
        if !(distance_squared >= MIN_LIGHT_DISTANCE_SQUARED) {
            return vec3<f32>(0.0);
        }
        distance = sqrt(distance_squared);
        wi = to_light / distance;
        // Inverse-square law: E = I / r² on a surface facing the light.
        irradiance = light.power / distance_squared;
    } else {
        wi = -light.position_or_direction;
        distance = bitcast<f32>(0x7f800000u); // +infinity
        irradiance = light.power;
    }
    let cos_i = clamp(dot(n, wi), -1.0, 1.0);
    if cos_i <= 0.0 {
        return vec3<f32>(0.0);
    }
    rays_traced += 1u;
    if occluded(Ray(origin, wi), distance) {
        return vec3<f32>(0.0);
    }
    return eval_brdf(material, n, wi, wo) * irradiance * cos_i;
}

// Shades a hit: emission, ambient and direct light with one shadow ray per light, and
// the reflected and refracted rays with their weights, for a ray inside `medium`. New
// rays start at the re-projected hit point moved off the surface (offset_ray_origin).
fn shade_hit(ray: Ray, hit: Hit, medium: MediumStack) -> ShadedHit {
    let position = hit.position;
    var material = materials[hit.material];
    material.diffuse = shading_albedo(material, position, hit.normal);
    let entering = dot(ray.direction, hit.normal) < 0.0;
    // Shading happens on the side the ray came from.
    let n = select(-hit.normal, hit.normal, entering);
    let wo = -ray.direction;
    //#if REFRACTION
    let outside_ior = medium_outside_ior(medium, entering);
    //#else
    // Without dielectrics every ray travels in air.
    let outside_ior = 1.0;
    //#endif
    let response = surface_response(material, ray.direction, n, entering, outside_ior);

    var radiance = material.emission;
    if has_base_brdf(material.kind) && response.base > 0.0 {
        var direct = material.diffuse * frame.ambient;
        let shadow_origin = offset_ray_origin(position, n, frame.offset_scale);
        for (var i = 0u; i < frame.light_count; i += 1u) {
            direct += direct_light(lights[i], material, shadow_origin, n, wo);
        }
        radiance += direct * response.base;
    }
    let reflected = Ray(offset_ray_origin(position, n, frame.offset_scale), normalize(reflect_direction(ray.direction, n)));
    //#if REFRACTION
    let transmitted = Ray(offset_ray_origin(position, -n, frame.offset_scale), response.transmit_direction);
    let transmitted_medium = medium_after_refraction(medium, entering, material.ior);
    //#else
    // No dielectric, no refracted ray (its weight is zero).
    let transmitted = reflected;
    let transmitted_medium = medium;
    //#endif
    return ShadedHit(radiance, response.reflect, reflected, response.transmit, transmitted,
                     transmitted_medium);
}

// Radiance arriving along `primary`: every reflected or refracted ray is pushed on a
// stack of STACK_SIZE entries and popped until none is left. Refraction is pushed
// first so reflection is traced first; a branch that finds the stack full, or whose
// weight is not above frame.min_ray_weight, is dropped. A contribution that is not
// finite_radiance is dropped: no NaN or infinity reaches the image.
fn trace_radiance(primary: Ray) -> vec3<f32> {
    var stack: array<StackEntry, STACK_SIZE>;
    // Camera rays start inside the dielectrics around the camera (camera_medium).
    stack[0] = StackEntry(primary, vec3<f32>(1.0), 0u,
                          MediumStack(frame.camera_medium_iors, frame.camera_medium_depth));
    var stack_length = 1u;
    var radiance = vec3<f32>(0.0);
    let infinity = bitcast<f32>(0x7f800000u);
    while stack_length > 0u {
        stack_length -= 1u;
        let entry = stack[stack_length];
        rays_traced += 1u;
        let hit = intersect_scene(entry.ray, infinity);
        if !hit.found {
            let contribution = entry.weight * frame.background;
            if finite_radiance(contribution) {
                radiance += contribution;
            }
            continue;
        }
        let shaded = shade_hit(entry.ray, hit, entry.medium);
        let contribution = entry.weight * shaded.radiance;
        if finite_radiance(contribution) {
            radiance += contribution;
        }
        if entry.depth >= frame.max_depth {
            continue;
        }
        //#if REFRACTION
        let transmit_weight = entry.weight * shaded.transmit_weight;
        if max(transmit_weight.x, max(transmit_weight.y, transmit_weight.z)) > frame.min_ray_weight && stack_length < STACK_SIZE {
            stack[stack_length] = StackEntry(shaded.transmitted, transmit_weight, entry.depth + 1u,
                                             shaded.transmitted_medium);
            stack_length += 1u;
        }
        //#endif
        let reflect_weight = entry.weight * shaded.reflect_weight;
        if max(reflect_weight.x, max(reflect_weight.y, reflect_weight.z)) > frame.min_ray_weight && stack_length < STACK_SIZE {
            stack[stack_length] = StackEntry(shaded.reflected, reflect_weight, entry.depth + 1u,
                                             entry.medium);
            stack_length += 1u;
        }
    }
    return radiance;
}

// One invocation per pixel of the dispatched region (rows row_offset.., columns
// column_offset..), tracing sample frame.sample_index. Samples are summed in the
// accumulation buffer in index order, as the CPU sums them; the dispatch of the last
// sample writes the mean (box filter) into the linear output at the pixel's position
// relative to the target's origin (target_x, target_y), which is (0, 0) unless the
// image is traced in tiles.
//
// One sample per dispatch, not a loop over samples: Mesa's llvmpipe/lavapipe ends
// every loop of an invocation once all loops together have run 65535 iterations
// (LP_MAX_TGSI_LOOP_ITERATIONS in gallivm), which a pixel with many samples of deep
// glass paths exceeds, silently losing rays.
@compute @workgroup_size(8, 8, 1)
fn trace_pixels(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.column_count || id.y >= frame.row_count {
        return;
    }
    let x = frame.column_offset + id.x;
    let y = frame.row_offset + id.y;
    let slot = id.y * frame.width + x;
    rays_traced = 0u;
    let offset = sample_offset(x, y, frame.sample_index);
    let direction = camera_ray_direction(f32(x) + offset.x, f32(y) + offset.y);
    var sum = trace_radiance(Ray(frame.eye, direction));
    if frame.sample_index > 0u {
        sum = accumulation[slot].xyz + sum;
    }
    if frame.sample_index + 1u < frame.samples_per_pixel {
        accumulation[slot] = vec4<f32>(sum, 0.0);
    } else {
        var radiance = sum / f32(frame.samples_per_pixel);
        // The sum of finite contributions may still overflow: the pixel is then black.
        if !finite_radiance(radiance) {
            radiance = vec3<f32>(0.0);
        }
        textureStore(linear_output, vec2<u32>(x - frame.target_x, y - frame.target_y), vec4<f32>(radiance, 1.0));
    }
    atomicAdd(&ray_counts[y], rays_traced);
}
