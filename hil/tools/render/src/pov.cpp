#include "sunvo/render/pov.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>

extern char** environ;

namespace sunvo::render {
namespace {
std::string num(double a) {
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", a);
  return b;
}
}  // namespace

std::string povVector(const Eigen::Vector3d& v) {
  char b[160];
  std::snprintf(b, sizeof b, "<%.9g,%.9g,%.9g>", v.x(), v.z(), v.y());
  return b;
}

std::string povCamera(const StereoCamera& cam, const Isometry3& T_enu_c) {
  const Eigen::Matrix3d C = T_enu_c.linear();
  const double W = cam.width, H = cam.height;
  const Eigen::Vector3d right = C * Eigen::Vector3d(W / cam.fu, 0.0, 0.0);
  const Eigen::Vector3d up = C * Eigen::Vector3d(0.0, -H / cam.fv, 0.0);
  const Eigen::Vector3d dir = C * Eigen::Vector3d((0.5 * (W - 1.0) - cam.cu) / cam.fu,
                                                  (0.5 * (H - 1.0) - cam.cv) / cam.fv, 1.0);
  return "camera { perspective location " + povVector(T_enu_c.translation()) + " direction " +
         povVector(dir) + " right " + povVector(right) + " up " + povVector(up) + " }\n";
}

std::string povSceneBody(const Scene& scene) {
  std::string s = scene.declarations;
  s += "plane { y, 0 texture { " + scene.ground_texture + " } }\n";
  return s + povPrimitives(scene.primitives);
}

std::string povPrimitives(const std::vector<Primitive>& primitives) {
  std::string s;
  s.reserve(primitives.size() * 200);
  for (const Primitive& p : primitives) {
    const bool named = p.texture.find(' ') == std::string::npos;
    const std::string tex =
        named ? "texture { " + p.texture + " }" : "texture { " + p.texture + " }";
    switch (p.kind) {
      case Primitive::Kind::kBox:
        s += "box { " + povVector(p.a) + ", " + povVector(p.b) + " " + tex + " }\n";
        break;
      case Primitive::Kind::kCylinder:
        s += "cylinder { " + povVector(p.a) + ", " + povVector(p.b) + ", " + num(p.radius) + " " +
             tex + " }\n";
        break;
      case Primitive::Kind::kSphere:
        s += "sphere { " + povVector(p.a) + ", " + num(p.radius) + " " + tex + " }\n";
        break;
      case Primitive::Kind::kCone:
        s += "cone { " + povVector(p.a) + ", " + num(p.radius) + ", " + povVector(p.b) + ", 0 " +
             tex + " }\n";
        break;
      case Primitive::Kind::kEllipsoid:  // unit sphere scaled by the semi-axes, then moved
        s += "sphere { <0,0,0>, 1 " + tex + " scale " + povVector(p.b) + " translate " +
             povVector(p.a) + " }\n";
        break;
    }
  }
  return s;
}

std::string povFrame(const std::vector<StereoCamera>& cams, const std::vector<Isometry3>& T_enu_c,
                     const Lighting& L, const std::string& include_file,
                     const Scene* inline_scene) {
  auto col = [](const Eigen::Vector3d& c) {
    char b[128];
    std::snprintf(b, sizeof b, "rgb <%.6g,%.6g,%.6g>", c.x(), c.y(), c.z());
    return std::string(b);
  };
  std::string s = "#version 3.7;\n";
  // Linear working space; ambient_light carries the sky's diffuse illuminance (no radiosity).
  s += "global_settings { assumed_gamma 1.0 max_trace_level 4 ambient_light " + col(L.ambient_rgb) +
       " }\n";
  s += "#default { finish { ambient 1 diffuse 1 } }\n";
  s += "#ifndef (CAM) #declare CAM = 0; #end\n";
  for (std::size_t k = 0; k < cams.size(); ++k) {
    s += "#if (CAM = " + std::to_string(k) + ")\n" + povCamera(cams[k], T_enu_c[k]) + "#end\n";
  }
  // The sun: a parallel light, its location far along sun_enu from the first camera (shadow
  // rays of a parallel light run along the direction location - point_at).
  Eigen::Vector3d c0 = Eigen::Vector3d::Zero();
  if (!T_enu_c.empty()) c0 = T_enu_c[0].translation();
  if (L.sun_enu.z() > 0.0) {
    s += "light_source { " + povVector(c0 + 5000.0 * L.sun_enu.normalized()) + " color " +
         col(L.sun_rgb) + " parallel point_at " + povVector(c0) + " }\n";
  }
  if (!L.sky_image.empty()) {
    s += "sky_sphere { pigment { image_map { hdr \"" + L.sky_image +
         "\" map_type 1 interpolate 2 } } }\n";
  } else {
    s += "sky_sphere { pigment { " + col(L.flat_sky_rgb) + " } }\n";
  }
  s += L.materials;
  if (!include_file.empty()) {
    s += "#include \"" + include_file + "\"\n";
  } else if (inline_scene != nullptr) {
    s += povSceneBody(*inline_scene);
  }
  return s;
}

Status RenderQuality::validate() const {
  if (!(antialias_threshold >= 0 && antialias_threshold <= 1))
    return invalidArgument("render.antialias_threshold out of range [0, 1]");
  if (!(antialias_depth >= 1 && antialias_depth <= 9))
    return invalidArgument("render.antialias_depth out of range [1, 9]");
  if (!(quality >= 0 && quality <= 11))
    return invalidArgument("render.quality out of range [0, 11]");
  return Status::ok();
}

namespace {
Expected<pid_t> spawnPovray(const RenderJob& job, const RenderQuality& q) {
  std::vector<std::string> args = {"povray",
                                   "+I" + job.pov_file,
                                   "+O" + job.output_png,
                                   "+W" + std::to_string(job.width),
                                   "+H" + std::to_string(job.height),
                                   "+FN",
                                   "-D",
                                   "-P",
                                   "-V",
                                   "+WT1",
                                   "+Q" + std::to_string(q.quality),
                                   "Declare=CAM=" + std::to_string(job.cam_index)};
  if (q.antialias_threshold > 0.0) {
    args.push_back("+A" + num(q.antialias_threshold));
    args.push_back("+R" + std::to_string(q.antialias_depth));
  } else {
    args.push_back("-A");
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The child changes directory first: POV-Ray's I/O restrictions allow the current directory.
  // posix_spawn has no chdir before glibc 2.29's addchdir_np; Debian 12 has glibc 2.36.
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addchdir_np(&fa, job.work_dir.c_str());
  const std::string log = job.log_file.empty() ? "/dev/null" : job.log_file;
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "povray", &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return ioError(std::string("cannot start povray: ") + std::strerror(rc));
  return pid;
}
}  // namespace

Status runPovrayJobs(const std::vector<RenderJob>& jobs, const RenderQuality& q, int max_parallel,
                     const std::function<void(std::size_t, const Status&)>& on_done) {
  SUNVO_RETURN_IF_ERROR(q.validate());
  if (max_parallel < 1) return invalidArgument("render jobs: max_parallel must be >= 1");
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0;
  Status first;
  while (next < jobs.size() || !running.empty()) {
    while (next < jobs.size() && static_cast<int>(running.size()) < max_parallel) {
      auto pid = spawnPovray(jobs[next], q);
      if (!pid) {
        if (first.isOk()) first = pid.status();
        if (on_done) on_done(next, pid.status());
        ++next;
        continue;
      }
      running[*pid] = next++;
    }
    if (running.empty()) continue;
    int wstatus = 0;
    const pid_t pid = waitpid(-1, &wstatus, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      return ioError(std::string("waitpid: ") + std::strerror(errno));
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    const std::size_t idx = it->second;
    running.erase(it);
    Status st;
    if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0) {
      st = ioError("povray failed for " + jobs[idx].work_dir + "/" + jobs[idx].pov_file + " (see " +
                   jobs[idx].log_file + ")");
      if (first.isOk()) first = st;
    }
    if (on_done) on_done(idx, st);
  }
  return first;
}

Status runPovray(const RenderJob& job, const RenderQuality& q) {
  return runPovrayJobs({job}, q, 1, nullptr);
}

}  // namespace sunvo::render
