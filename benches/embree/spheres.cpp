// The peer of `raystep bench` on many spheres: Intel Embree 3 tracing the same
// scene, camera and paths as raystep's fast engine, so that rays per second
// compare. Not part of raystep, not run by its tests; `benches/embree/run.sh`
// builds it and measures both side by side (README and chapter 10 give the
// commands).
//
// What it traces, as raystep's `Tracer::trace` does (chapter 6): one primary ray
// per pixel through the tutorial's screen; at each hit, the normal, the point
// stepped off the surface by raystep's `auto` offset, a shadow ray to the light
// unless the point faces away from it (then, as with any hit closer than the
// light, the path ends), Blinn-Phong seen from the
// camera, and a mirrored ray, up to `max_depth` segments, with raystep's early
// stop (a path ends once nothing the rest of it can add would move a channel by
// half an 8-bit step). The spheres (the floor's huge sphere too) are one Embree
// user geometry whose callbacks run raystep's stable sphere test (Ray Tracing
// Gems, chapter 7) in float32, Embree's precision; with `--builtin` they are
// Embree's own sphere primitive instead (RTC_GEOMETRY_TYPE_SPHERE_POINT), whose
// test is Embree's SIMD code. Rays go eight at a time: a packet of 4 × 2
// pixels (rtcIntersect8 and rtcOccluded8, the shadow and mirrored rays of a
// packet as one packet each). Rows of packets are shared among `--threads`
// threads.
//
// The scene is a raystep scene file as `raystep generate spheres` writes it (or
// scenes/seed.toml): [image], [camera] position, [light], [render] max_depth,
// [[sphere]] and [[plane]] entries given as a sphere (`sphere = { center = …,
// radius = … }`), each key on its own line. A true plane is refused.
//
// Output: one CSV header and one row (see `main`). The tree build is timed on
// its own (rtcCommitScene, with Embree's own threads) and not counted in the
// frame.
//
//   spheres [--width W] [--height H] [--threads N] [--runs R] [--without-reflection]
//           [--builtin] [--quality low|medium|high] [--ppm FILE] SCENE|-

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

struct V {
  float x = 0, y = 0, z = 0;
};
inline V operator+(V a, V b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V operator-(V a, V b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V operator*(V a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline V operator*(V a, V b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline float dot(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V normalize(V a) { return a * (1.0f / std::sqrt(dot(a, a))); }
inline float max_abs(V a) { return std::max(std::fabs(a.x), std::max(std::fabs(a.y), std::fabs(a.z))); }

struct Ball {
  V centre;
  float radius;
  V ambient, diffuse, specular;
  float shininess, reflection;
};

struct Scene {
  int width = 300, height = 200, max_depth = 3;
  V camera{0, 0, 1};
  V light{5, 5, 5}, light_ambient{1, 1, 1}, light_diffuse{1, 1, 1}, light_specular{1, 1, 1};
  std::vector<Ball> balls;
};

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "spheres: " << message << "\n";
  std::exit(2);
}

// Embree's advice for every thread that traces: flush denormals to zero.
void denormals_off() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

// The numbers of `text` after the first '=' (a number or a list [a, b, c];
// inline tables give theirs in order).
std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  const char* p = text.c_str();
  while (*p) {
    if ((*p >= '0' && *p <= '9') || *p == '-' || *p == '+' || *p == '.') {
      char* end;
      double v = std::strtod(p, &end);
      if (end != p) {
        out.push_back(v);
        p = end;
        continue;
      }
    }
    ++p;
  }
  return out;
}

V triple(const std::vector<double>& n, const std::string& line) {
  if (n.size() != 3) fail("expected three numbers: " + line);
  return {float(n[0]), float(n[1]), float(n[2])};
}

Scene parse(std::istream& in) {
  Scene scene;
  std::string section, line;
  Ball* ball = nullptr;
  auto fresh = [&] {
    scene.balls.push_back(Ball{{0, 0, 0}, 1, {0.1f, 0.1f, 0.1f}, {0.6f, 0.6f, 0.6f}, {1, 1, 1}, 100, 0.5f});
    ball = &scene.balls.back();
  };
  while (std::getline(in, line)) {
    auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    line = line.substr(first);
    if (line[0] == '[') {
      section = line.substr(0, line.find(']', line[1] == '[' ? 2 : 1) + (line[1] == '[' ? 2 : 1));
      ball = nullptr;
      if (section == "[[sphere]]" || section == "[[plane]]") fresh();
      continue;
    }
    auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    std::string key = line.substr(0, line.find_first_of(" \t="));
    auto n = numbers(line.substr(eq + 1));
    if (section == "[image]") {
      if (key == "width") scene.width = int(n.at(0));
      if (key == "height") scene.height = int(n.at(0));
    } else if (section == "[camera]") {
      if (key == "position") scene.camera = triple(n, line);
    } else if (section == "[light]") {
      if (key == "position") scene.light = triple(n, line);
      if (key == "ambient") scene.light_ambient = triple(n, line);
      if (key == "diffuse") scene.light_diffuse = triple(n, line);
      if (key == "specular") scene.light_specular = triple(n, line);
    } else if (section == "[render]") {
      if (key == "max_depth") scene.max_depth = int(n.at(0));
    } else if (ball) {
      if (key == "center") ball->centre = triple(n, line);
      else if (key == "radius") ball->radius = float(n.at(0));
      else if (key == "sphere") {
        if (n.size() != 4) fail("expected sphere = { center = [x, y, z], radius = r }: " + line);
        ball->centre = {float(n[0]), float(n[1]), float(n[2])};
        ball->radius = float(n[3]);
      } else if (key == "point" || key == "normal") {
        fail("a true plane (point, normal) is not supported: only spheres");
      } else if (key == "ambient") ball->ambient = triple(n, line);
      else if (key == "diffuse") ball->diffuse = triple(n, line);
      else if (key == "specular") ball->specular = triple(n, line);
      else if (key == "shininess") ball->shininess = float(n.at(0));
      else if (key == "reflection") ball->reflection = float(n.at(0));
    }
  }
  return scene;
}

const Ball* g_balls = nullptr;

// raystep's stable sphere test (src/sphere.rs): a hit only where both crossings
// lie in front of the origin; the nearer one, if within (tnear, tfar).
inline bool sphere_hit(const Ball& b, V o, V d, float tnear, float tfar, float& t) {
  V f = o - b.centre;
  float d_dot_f = dot(d, f);
  if (d_dot_f > 0) return false;  // heading away: both crossings behind
  float r2 = b.radius * b.radius;
  float h = -d_dot_f;
  V closest = f + d * h;
  float quarter_delta = r2 - dot(closest, closest);
  if (!(quarter_delta > 0)) return false;
  float root = std::sqrt(quarter_delta);
  float q = h + (h >= 0 ? root : -root);
  if (q == 0) return false;
  float c = dot(f, f) - r2;
  float t1 = c / q;
  float near = std::min(t1, q), far = std::max(t1, q);
  if (!(near > 0 && far > 0)) return false;
  if (!(near > tnear && near < tfar)) return false;
  t = near;
  return true;
}

void bounds(const RTCBoundsFunctionArguments* a) {
  const Ball& b = g_balls[a->primID];
  // Widened by a few float32 roundings of the centre's size, as raystep's boxes.
  float pad = b.radius + 64.0f * 6e-8f * (max_abs(b.centre) + b.radius);
  a->bounds_o->lower_x = b.centre.x - pad;
  a->bounds_o->lower_y = b.centre.y - pad;
  a->bounds_o->lower_z = b.centre.z - pad;
  a->bounds_o->upper_x = b.centre.x + pad;
  a->bounds_o->upper_y = b.centre.y + pad;
  a->bounds_o->upper_z = b.centre.z + pad;
}

void intersect(const RTCIntersectFunctionNArguments* a) {
  const Ball& b = g_balls[a->primID];
  const unsigned N = a->N;
  RTCRayN* ray = RTCRayHitN_RayN(a->rayhit, N);
  RTCHitN* hit = RTCRayHitN_HitN(a->rayhit, N);
  for (unsigned i = 0; i < N; i++) {
    if (!a->valid[i]) continue;
    V o{RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i)};
    V d{RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)};
    float t;
    if (!sphere_hit(b, o, d, RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i), t)) continue;
    RTCRayN_tfar(ray, N, i) = t;
    RTCHitN_geomID(hit, N, i) = a->geomID;
    RTCHitN_primID(hit, N, i) = a->primID;
    RTCHitN_u(hit, N, i) = 0;
    RTCHitN_v(hit, N, i) = 0;
    RTCHitN_instID(hit, N, i, 0) = RTC_INVALID_GEOMETRY_ID;
  }
}

void occluded(const RTCOccludedFunctionNArguments* a) {
  const Ball& b = g_balls[a->primID];
  const unsigned N = a->N;
  RTCRayN* ray = a->ray;
  for (unsigned i = 0; i < N; i++) {
    if (!a->valid[i]) continue;
    V o{RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i)};
    V d{RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)};
    float t;
    if (sphere_hit(b, o, d, RTCRayN_tnear(ray, N, i), RTCRayN_tfar(ray, N, i), t))
      RTCRayN_tfar(ray, N, i) = -INFINITY;  // Embree's mark of an occluded ray
  }
}

struct Counts {
  uint64_t primary = 0, shadow = 0, reflection = 0;
};

constexpr int W = 8;  // rays per packet
constexpr float HALF_STEP = 0.5f / 255.0f;
constexpr float RADIUS_UNITS = 7.0f;  // raystep's auto step: u·(7·r + 2·‖P‖)
constexpr float POINT_UNITS = 2.0f;
constexpr float STEP_CAP = 1e38f;     // raystep's STEP_CAP
constexpr float U32 = 5.9604645e-8f;                // float32's unit roundoff

struct Renderer {
  const Scene& scene;
  RTCScene rtc;
  bool reflection;
  std::vector<float> reach;  // raystep's early-stop bound (src/render.rs `reach`)
  std::vector<float> rgb;

  Renderer(const Scene& s, RTCScene r, bool refl) : scene(s), rtc(r), reflection(refl) {
    float most = 0, mirror = 0;
    for (const Ball& b : s.balls) {
      V t{std::fabs(b.ambient.x * s.light_ambient.x) + std::fabs(b.diffuse.x * s.light_diffuse.x) +
              std::fabs(b.specular.x * s.light_specular.x),
          std::fabs(b.ambient.y * s.light_ambient.y) + std::fabs(b.diffuse.y * s.light_diffuse.y) +
              std::fabs(b.specular.y * s.light_specular.y),
          std::fabs(b.ambient.z * s.light_ambient.z) + std::fabs(b.diffuse.z * s.light_diffuse.z) +
              std::fabs(b.specular.z * s.light_specular.z)};
      most = std::max(most, std::max(t.x, std::max(t.y, t.z)));
      mirror = std::max(mirror, std::fabs(b.reflection));
    }
    reach.assign(s.max_depth + 1, 0.0f);
    for (size_t k = 1; k < reach.size(); k++) reach[k] = most + mirror * reach[k - 1];
    rgb.assign(size_t(s.width) * s.height * 3, 0.0f);
  }

  // The screen point of column `col` (row `row`): numpy's linspace, as raystep.
  static float linspace(float from, float to, int i, int n) {
    if (n == 1) return from;
    float step = (to - from) / float(n - 1);
    return i == n - 1 ? to : from + step * float(i);
  }

  // Trace the packet of pixels (x0..x0+3, y0..y0+1).
  void packet(int x0, int y0, Counts& counts) {
    const Scene& s = scene;
    const float ratio = float(s.width) / float(s.height);
    alignas(32) int valid[W];
    alignas(32) RTCRayHit8 rh;
    alignas(32) RTCRay8 shadow;
    V colour[W], weight[W];
    int pixel[W];
    bool alive[W];
    for (int k = 0; k < W; k++) {
      int x = x0 + (k & 3), y = y0 + (k >> 2);
      bool in = x < s.width && y < s.height;
      pixel[k] = in ? y * s.width + x : -1;
      alive[k] = in;
      colour[k] = {0, 0, 0};
      weight[k] = {1, 1, 1};
      V target{linspace(-1, 1, x, s.width), linspace(1 / ratio, -1 / ratio, y, s.height), 0};
      V d = normalize(target - s.camera);
      rh.ray.org_x[k] = s.camera.x;
      rh.ray.org_y[k] = s.camera.y;
      rh.ray.org_z[k] = s.camera.z;
      rh.ray.dir_x[k] = d.x;
      rh.ray.dir_y[k] = d.y;
      rh.ray.dir_z[k] = d.z;
      if (in) counts.primary++;
    }
    const int segments = reflection ? s.max_depth : 1;
    RTCIntersectContext context;
    for (int segment = 0; segment < segments; segment++) {
      int any = 0;
      for (int k = 0; k < W; k++) {
        valid[k] = alive[k] ? -1 : 0;
        any |= valid[k];
        rh.ray.tnear[k] = 0;
        rh.ray.tfar[k] = INFINITY;
        rh.ray.mask[k] = 0xFFFFFFFF;
        rh.ray.flags[k] = 0;
        rh.ray.time[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      }
      if (!any) break;
      if (segment > 0)
        for (int k = 0; k < W; k++) counts.reflection += alive[k];
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      rtcIntersect8(valid, rtc, &context, &rh);
      V point[W], normal[W], shifted[W], to_light[W];
      float light_distance[W];
      int shadowed = 0;
      for (int k = 0; k < W; k++) {
        valid[k] = 0;
        if (!alive[k]) continue;
        if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
          alive[k] = false;
          continue;
        }
        const Ball& b = g_balls[rh.hit.primID[k]];
        V o{rh.ray.org_x[k], rh.ray.org_y[k], rh.ray.org_z[k]};
        V d{rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
        point[k] = o + d * rh.ray.tfar[k];
        V from_centre = point[k] - b.centre;
        normal[k] = normalize(from_centre);
        // raystep's `auto` step (`sphere_step`, chapter 9): back onto the
        // sphere and out by u·(7·r + 2·‖P‖), in one move.
        float back = b.radius - std::sqrt(dot(from_centre, from_centre));
        float height = U32 * (RADIUS_UNITS * b.radius +
                              POINT_UNITS * std::sqrt(dot(point[k], point[k])));
        shifted[k] = point[k] + normal[k] * (back + std::min(height, STEP_CAP));
        V l = s.light - shifted[k];
        to_light[k] = normalize(l);
        if (dot(normal[k], to_light[k]) < 0) {
          // Its own sphere hides the light (raystep's `own_shadow`): the path
          // ends, black, and no shadow ray is cast.
          alive[k] = false;
          continue;
        }
        V lp = s.light - point[k];
        light_distance[k] = std::sqrt(dot(lp, lp));
        shadow.org_x[k] = shifted[k].x;
        shadow.org_y[k] = shifted[k].y;
        shadow.org_z[k] = shifted[k].z;
        shadow.dir_x[k] = to_light[k].x;
        shadow.dir_y[k] = to_light[k].y;
        shadow.dir_z[k] = to_light[k].z;
        shadow.tnear[k] = 0;
        shadow.tfar[k] = light_distance[k];
        shadow.mask[k] = 0xFFFFFFFF;
        shadow.flags[k] = 0;
        shadow.time[k] = 0;
        valid[k] = -1;
        shadowed = 1;
        counts.shadow++;
      }
      if (!shadowed) break;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      rtcOccluded8(valid, rtc, &context, &shadow);
      for (int k = 0; k < W; k++) {
        if (!alive[k]) continue;
        if (shadow.tfar[k] < 0) {  // in shadow: the path ends, black
          alive[k] = false;
          continue;
        }
        const Ball& b = g_balls[rh.hit.primID[k]];
        V to_viewer = normalize(s.camera - point[k]);
        float l_dot_n = dot(to_light[k], normal[k]);
        V half = normalize(to_light[k] + to_viewer);
        float n_dot_h = std::max(dot(normal[k], half), 0.0f);
        float highlight = std::pow(n_dot_h, b.shininess / 4.0f);
        V sum = b.ambient * s.light_ambient + b.diffuse * s.light_diffuse * l_dot_n +
                b.specular * s.light_specular * highlight;
        colour[k] = colour[k] + sum * weight[k];
        weight[k] = weight[k] * b.reflection;
        V d{rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
        V r = d - normal[k] * (2.0f * dot(d, normal[k]));
        rh.ray.org_x[k] = shifted[k].x;
        rh.ray.org_y[k] = shifted[k].y;
        rh.ray.org_z[k] = shifted[k].z;
        rh.ray.dir_x[k] = r.x;
        rh.ray.dir_y[k] = r.y;
        rh.ray.dir_z[k] = r.z;
        size_t left = size_t(segments - segment - 1);
        if (left < reach.size() && weight[k].x * reach[left] < HALF_STEP) alive[k] = false;
      }
    }
    for (int k = 0; k < W; k++) {
      if (pixel[k] < 0) continue;
      float* p = &rgb[size_t(pixel[k]) * 3];
      p[0] = std::min(std::max(colour[k].x, 0.0f), 1.0f);
      p[1] = std::min(std::max(colour[k].y, 0.0f), 1.0f);
      p[2] = std::min(std::max(colour[k].z, 0.0f), 1.0f);
    }
  }

  Counts frame(int threads) {
    const int rows = (scene.height + 1) / 2, columns = (scene.width + 3) / 4;
    std::atomic<int> next{0};
    std::vector<Counts> per(threads);
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; t++)
      pool.emplace_back([&, t] {
        denormals_off();
        for (int r; (r = next.fetch_add(1)) < rows;)
          for (int c = 0; c < columns; c++) packet(c * 4, r * 2, per[t]);
      });
    for (auto& th : pool) th.join();
    Counts all;
    for (auto& c : per) {
      all.primary += c.primary;
      all.shadow += c.shadow;
      all.reflection += c.reflection;
    }
    return all;
  }
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  int width = 0, height = 0, runs = 5;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  bool reflection = true, builtin = false;
  std::string path, ppm, quality = "medium";
  for (int i = 1; i < argc; i++) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fail(a + " needs a value");
      return argv[++i];
    };
    if (a == "--width") width = std::atoi(value().c_str());
    else if (a == "--height") height = std::atoi(value().c_str());
    else if (a == "--threads") threads = std::atoi(value().c_str());
    else if (a == "--runs") runs = std::atoi(value().c_str());
    else if (a == "--without-reflection") reflection = false;
    else if (a == "--builtin") builtin = true;
    else if (a == "--quality") quality = value();
    else if (a == "--ppm") ppm = value();
    else if (a.size() > 1 && a[0] == '-') fail("unknown option " + a);
    else path = a;
  }
  if (path.empty()) fail("usage: spheres [options] SCENE.toml|-");
  Scene scene;
  if (path == "-") {
    scene = parse(std::cin);
  } else {
    std::ifstream file(path);
    if (!file) fail("cannot read " + path);
    scene = parse(file);
  }
  if (width > 0) scene.width = width;
  if (height > 0) scene.height = height;
  if (threads < 1 || runs < 1 || scene.balls.empty()) fail("nothing to do");
  g_balls = scene.balls.data();

  denormals_off();
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) fail("rtcNewDevice failed");
  {
    // Start Embree's threads before the build is timed: commit an empty scene.
    RTCScene warm = rtcNewScene(device);
    rtcCommitScene(warm);
    rtcReleaseScene(warm);
  }
  auto start = std::chrono::steady_clock::now();
  RTCScene rtc = rtcNewScene(device);
  RTCBuildQuality q = quality == "low" ? RTC_BUILD_QUALITY_LOW
                      : quality == "high" ? RTC_BUILD_QUALITY_HIGH
                                          : RTC_BUILD_QUALITY_MEDIUM;
  rtcSetSceneBuildQuality(rtc, q);
  const unsigned n = unsigned(scene.balls.size());
  RTCGeometry geometry;
  if (builtin) {
    geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                           RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
    for (unsigned i = 0; i < n; i++) {
      const Ball& b = scene.balls[i];
      v[4 * i] = b.centre.x;
      v[4 * i + 1] = b.centre.y;
      v[4 * i + 2] = b.centre.z;
      v[4 * i + 3] = b.radius;
    }
  } else {
    geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, n);
    rtcSetGeometryBoundsFunction(geometry, bounds, nullptr);
    rtcSetGeometryIntersectFunction(geometry, intersect);
    rtcSetGeometryOccludedFunction(geometry, occluded);
  }
  rtcSetGeometryBuildQuality(geometry, q);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(rtc, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(rtc);
  const double build_s = seconds_since(start);

  Renderer renderer(scene, rtc, reflection);
  Counts counts = renderer.frame(threads);  // warm-up
  std::vector<double> times;
  for (int r = 0; r < runs; r++) {
    auto t0 = std::chrono::steady_clock::now();
    counts = renderer.frame(threads);
    times.push_back(seconds_since(t0));
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  const size_t m = sorted.size();
  const double median = m % 2 ? sorted[m / 2] : (sorted[m / 2 - 1] + sorted[m / 2]) / 2;
  const uint64_t rays = counts.primary + counts.shadow + counts.reflection;
  std::printf(
      "objects,width,height,threads,runs,geometry,build_ms,median_ms,min_ms,max_ms,rays,"
      "rays_primary,rays_shadow,rays_reflection,mrays_per_s\n");
  std::printf("%u,%d,%d,%d,%d,%s,%.3f,%.3f,%.3f,%.3f,%llu,%llu,%llu,%llu,%.2f\n",
              n, scene.width, scene.height, threads, runs, builtin ? "builtin" : "user",
              build_s * 1e3, median * 1e3, sorted.front() * 1e3, sorted.back() * 1e3,
              (unsigned long long)rays, (unsigned long long)counts.primary,
              (unsigned long long)counts.shadow, (unsigned long long)counts.reflection,
              double(rays) / median / 1e6);
  if (!ppm.empty()) {
    std::ofstream out(ppm, std::ios::binary);
    out << "P6\n" << scene.width << " " << scene.height << "\n255\n";
    for (float c : renderer.rgb) out.put(char(int(c * 255.0f + 0.5f)));
  }
  rtcReleaseScene(rtc);
  rtcReleaseDevice(device);
  return 0;
}
