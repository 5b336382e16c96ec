#include "baseline/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>

#include "util/error.h"
#include "util/parallel.h"
#include "util/timer.h"

namespace gdpt {
namespace {

// Embree reports errors through a callback; the first one is kept and thrown after the call.
struct ErrorSink {
    std::mutex mutex;
    std::string message;
};

void onEmbreeError(void* user, RTCError code, const char* message) {
    auto* sink = static_cast<ErrorSink*>(user);
    std::lock_guard<std::mutex> lock(sink->mutex);
    if (sink->message.empty())
        sink->message =
            "Embree error " + std::to_string(static_cast<int>(code)) + ": " + (message ? message : "");
}

}  // namespace

struct EmbreeScene::Impl {
    ErrorSink errors;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    double buildMs = 0.0;
    const std::vector<glm::vec3>& positions;
    const std::vector<glm::uvec3>& triangles;

    Impl(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& t) : positions(p), triangles(t) {}
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
    void check(const char* what) {
        std::lock_guard<std::mutex> lock(errors.mutex);
        if (!errors.message.empty())
            throw Error(std::string("Embree baseline: ") + what + ": " + errors.message);
    }
};

EmbreeScene::EmbreeScene(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                         std::uint32_t threads)
    : impl_(std::make_unique<Impl>(positions, triangles)) {
    const std::string config = "threads=" + std::to_string(std::max(1u, threads));
    impl_->device = rtcNewDevice(config.c_str());
    if (!impl_->device)
        throw Error("Embree baseline: rtcNewDevice(\"" + config + "\") failed (error " +
                    std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, &impl_->errors);
    impl_->scene = rtcNewScene(impl_->device);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
    auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangles.size()));
    impl_->check("allocating the geometry");
    if (!positions.empty()) std::memcpy(vertices, positions.data(), positions.size() * sizeof(glm::vec3));
    if (!triangles.empty()) std::memcpy(indices, triangles.data(), triangles.size() * sizeof(glm::uvec3));
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(impl_->scene, geometry);
    rtcReleaseGeometry(geometry);
    impl_->check("setting up the geometry");
    Timer timer;
    rtcCommitScene(impl_->scene);
    impl_->buildMs = timer.ms();
    impl_->check("building the BVH");
}

EmbreeScene::~EmbreeScene() = default;

double EmbreeScene::buildMs() const {
    return impl_->buildMs;
}

EmbreeHit EmbreeScene::intersect(glm::vec3 origin, glm::vec3 direction, float tMin, float tMax) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = origin.x;
    rh.ray.org_y = origin.y;
    rh.ray.org_z = origin.z;
    rh.ray.dir_x = direction.x;
    rh.ray.dir_y = direction.y;
    rh.ray.dir_z = direction.z;
    rh.ray.tnear = tMin;
    rh.ray.tfar = tMax;
    rh.ray.mask = std::numeric_limits<unsigned>::max();
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &context, &rh);
    EmbreeHit h;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    h.t = rh.ray.tfar;
    h.triangle = rh.hit.primID;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
    return h;
}

EmbreeScene::RayRun EmbreeScene::traceBenchPaths(const gpu::SceneConstants& c, std::uint32_t spp,
                                                 bool incoherent, std::uint32_t seed,
                                                 std::uint32_t threads) const {
    const auto& positions = impl_->positions;
    const auto& triangles = impl_->triangles;
    auto trace = [&](glm::vec3 o, glm::vec3 d) {
        const EmbreeHit e = intersect(o, d, 0.0f, std::numeric_limits<float>::infinity());
        BenchHit h;
        if (e.triangle == gpu::kInvalidIndex) return h;
        // The kernel's hit point and edges: v0 + u·e1 + v·e2 with e1 = p1 - p0, e2 = p2 - p0.
        const glm::uvec3 tri = triangles[e.triangle];
        h.hit = true;
        h.e1 = positions[tri.y] - positions[tri.x];
        h.e2 = positions[tri.z] - positions[tri.x];
        h.point = positions[tri.x] + e.u * h.e1 + e.v * h.e2;
        return h;
    };
    // One count per row, summed in row order once every thread has stopped.
    std::vector<BenchPathCount> counts(c.height);
    RayRun run;
    const double cpu0 = processCpuSeconds();
    Timer timer;
    parallelFor(threads, c.height, [&](std::size_t y) {
        for (std::uint32_t x = 0; x < c.width; ++x) {
            const BenchPathCount p =
                benchPixelPaths(c, x, static_cast<std::uint32_t>(y), spp, 0, seed, incoherent, trace);
            counts[y].rays += p.rays;
            counts[y].hits += p.hits;
        }
    });
    run.seconds = timer.ms() * 1e-3;
    run.cpuSeconds = processCpuSeconds() - cpu0;
    for (const BenchPathCount& p : counts) {
        run.count.rays += p.rays;
        run.count.hits += p.hits;
    }
    impl_->check("tracing");
    return run;
}

}  // namespace gdpt
