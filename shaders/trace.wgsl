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

// Rays traced by this invocation (camera, shadow and secondary).
var<private> rays_traced: u32;

struct StackEntry {
    ray: Ray,
    // Product of the weights of the bounces that led here.
    weight: vec3<f32>,
    // Bounces since the primary ray.
    depth: u32,
}

struct ShadedHit {
    // Emitted plus directly lit (and ambient) radiance towards the eye.
    radiance: vec3<f32>,
    reflect_weight: vec3<f32>,
    reflected: Ray,
    transmit_weight: vec3<f32>,
    transmitted: Ray,
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
        if distance_squared == 0.0 {
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
// the reflected and refracted rays with their weights.
fn shade_hit(ray: Ray, hit: Hit) -> ShadedHit {
    let position = ray_at(ray, hit.t);
    var material = materials[hit.material];
    material.diffuse = shading_albedo(material, position, hit.normal);
    let entering = dot(ray.direction, hit.normal) < 0.0;
    // Shading happens on the side the ray came from.
    let n = select(-hit.normal, hit.normal, entering);
    let wo = -ray.direction;
    let response = surface_response(material, ray.direction, n, entering);

    var radiance = material.emission;
    if has_base_brdf(material.kind) && response.base > 0.0 {
        var direct = material.diffuse * frame.ambient;
        let shadow_origin = offset_ray_origin(position, n);
        for (var i = 0u; i < frame.light_count; i += 1u) {
            direct += direct_light(lights[i], material, shadow_origin, n, wo);
        }
        radiance += direct * response.base;
    }
    let reflected = Ray(offset_ray_origin(position, n), normalize(reflect_direction(ray.direction, n)));
    let transmitted = Ray(offset_ray_origin(position, -n), response.transmit_direction);
    return ShadedHit(radiance, response.reflect, reflected, response.transmit, transmitted);
}

// Radiance arriving along `primary`: every reflected or refracted ray is pushed on a
// stack of STACK_SIZE entries and popped until none is left. Refraction is pushed
// first so reflection is traced first; a branch that finds the stack full is dropped.
fn trace_radiance(primary: Ray) -> vec3<f32> {
    var stack: array<StackEntry, STACK_SIZE>;
    stack[0] = StackEntry(primary, vec3<f32>(1.0), 0u);
    var stack_length = 1u;
    var radiance = vec3<f32>(0.0);
    let infinity = bitcast<f32>(0x7f800000u);
    while stack_length > 0u {
        stack_length -= 1u;
        let entry = stack[stack_length];
        rays_traced += 1u;
        let hit = intersect_scene(entry.ray, infinity);
        if !hit.found {
            radiance += entry.weight * frame.background;
            continue;
        }
        let shaded = shade_hit(entry.ray, hit);
        radiance += entry.weight * shaded.radiance;
        if entry.depth >= frame.max_depth {
            continue;
        }
        let transmit_weight = entry.weight * shaded.transmit_weight;
        if max(transmit_weight.x, max(transmit_weight.y, transmit_weight.z)) > 0.0 && stack_length < STACK_SIZE {
            stack[stack_length] = StackEntry(shaded.transmitted, transmit_weight, entry.depth + 1u);
            stack_length += 1u;
        }
        let reflect_weight = entry.weight * shaded.reflect_weight;
        if max(reflect_weight.x, max(reflect_weight.y, reflect_weight.z)) > 0.0 && stack_length < STACK_SIZE {
            stack[stack_length] = StackEntry(shaded.reflected, reflect_weight, entry.depth + 1u);
            stack_length += 1u;
        }
    }
    return radiance;
}

// One invocation per pixel of the dispatched row chunk; all samples of the pixel are
// averaged (box filter) into the linear output.
@compute @workgroup_size(8, 8, 1)
fn trace_pixels(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.width || id.y >= frame.row_count {
        return;
    }
    let x = id.x;
    let y = frame.row_offset + id.y;
    rays_traced = 0u;
    var sum = vec3<f32>(0.0);
    for (var index = 0u; index < frame.samples_per_pixel; index += 1u) {
        let offset = sample_offset(x, y, index);
        let direction = camera_ray_direction(f32(x) + offset.x, f32(y) + offset.y);
        sum += trace_radiance(Ray(frame.eye, direction));
    }
    let radiance = sum / f32(frame.samples_per_pixel);
    textureStore(linear_output, vec2<u32>(x, y), vec4<f32>(radiance, 1.0));
    atomicAdd(&ray_counts[y], rays_traced);
}
