#include "common/live.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/health.h"
#include "common/live_server.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/source_dir.h"
#include "common/summary.h"
#include "common/timer.h"
#include "common/trajectory.h"

namespace cl {

namespace {

std::string read_text(const std::string& path, const char* hint) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(std::string("--live: ") + path + " not found (" + hint + ")");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void replace_once(std::string& text, const std::string& mark, const std::string& with) {
  const std::size_t at = text.find(mark);
  if (at != std::string::npos) text.replace(at, mark.size(), with);
}

// A particle held by a client: its target and the positions of its last few
// steps (the release velocity), and the inverse mass it had.
struct Hold {
  int client = 0;
  double inv_mass = 0.0;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> trail;  // newest last, at most kTrail
  std::vector<double> trail_dt;        // the step each trail position came after, s (trail_dt[0] unused)
};
constexpr std::size_t kTrail = 4;

using Clock = std::chrono::steady_clock;

// How long a stop (the page's, Ctrl-C, SIGTERM) waits for the step under way
// before the run ends without it.
constexpr double kStopGraceSeconds = 0.5;
// The most changes (a drag, a pin, a knob, a reset) a page may have waiting
// for the step under way; more are refused.
constexpr std::size_t kWaitingPerClient = 64;

// The lab's step, on a thread of its own: the live loop goes on taking the
// pages' messages and watching for a stop while it runs, however long it takes
// (the student's code cannot be asked to look at a stop flag).
class StepThread {
 public:
  StepThread() : thread_([this] { work(); }) {}
  ~StepThread() {  // only when no job runs (run_live ends the process rather than wait for one)
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  StepThread(const StepThread&) = delete;
  StepThread& operator=(const StepThread&) = delete;

  void start(std::function<void()> job) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      job_ = std::move(job);
      done_ = false;
    }
    wake_.notify_all();
  }
  // Whether the job has ended, waiting up to `seconds`; rethrows what it threw (NotImplemented: exit 3).
  bool wait(double seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!finished_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; })) return false;
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return true;
  }

 private:
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return quit_ || job_; });
      if (quit_) return;
      std::function<void()> job = std::move(job_);
      job_ = nullptr;
      lock.unlock();
      std::exception_ptr error;
      try {
        job();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      done_ = true;
      finished_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::function<void()> job_;
  std::exception_ptr error_;
  bool done_ = true, quit_ = false;
  std::thread thread_;  // last: started once the rest is ready
};

}  // namespace

std::string live_page() {
  const std::string three = std::string(source_dir()) + "/tools/cl/vendor/three/";  // npm's three@0.111.0
  const char* hint = "the course's tree";
  std::string page = read_text(std::string(source_dir()) + "/tools/cl/live_page.html", "the course's tree");
  replace_once(page, "<!--three-->",
               "<script>\n" + read_text(three + "three.min.js", hint) + "\n</script>\n<script>\n" +
                   read_text(three + "OrbitControls.js", hint) + "\n</script>");
  replace_once(page, "<!--player-->",
               "<script>\n" + read_text(std::string(source_dir()) + "/tools/cl/view_player.js", "the course's tree") +
                   "\n</script>");
  return page;
}

int run_live(Scene& scene, const LiveOptions& options, const LiveRun& run, const std::string& summary_path) {
  stop_if_checking();  // --check: no server is started
  Particles& state = scene.particles;
  const Particles start = state;
  const Eigen::Index n = state.size();
  double free_inv_mass = 0.0;  // for freeing a particle the scene pinned: the mean of the free ones'
  int free_count = 0;
  for (Eigen::Index p = 0; p < n; ++p) {
    if (start.inv_mass[p] > 0.0) free_inv_mass += start.inv_mass[p], ++free_count;
  }
  free_inv_mass = free_count > 0 ? free_inv_mass / free_count : 1.0;

  Knobs knobs = run.knobs;
  Knobs stepped_with = knobs;  // the values the last step was taken with
  const int dt_knob = knobs.find("dt");
  auto dt_now = [&] { return dt_knob >= 0 ? knobs[static_cast<std::size_t>(dt_knob)] : scene.dt; };
  auto energy_of = [&](const Particles& particles) {
    return run.energy ? run.energy(particles)
                      : kinetic_energy(particles) + potential_energy(particles, scene.gravity);
  };

  LiveServer server(options.port, live_page());
  std::printf("%s\n", server.url().c_str());
  std::fflush(stdout);

  std::map<int, Hold> holds;   // by particle
  std::map<int, long> sent;    // per client: the version of the state it was last sent
  std::set<int> greeted;       // clients sent the hello: only they get frames (a frame before it has no mesh)
  long version = 0;            // the state's, +1 at every change the page should see
  int frame = 0, steps_done = 0;
  double time = 0.0, seconds = 0.0, last_step_seconds = 0.0, previous_step_seconds = 0.0, speed = 1.0;
  bool paused = false, stop = false, step_once = false, rebase = true, energy_noted = false;
  std::string rebuilt;  // what the lab rebuilt before the last step ("": nothing)
  // The last rebuild, kept in every status: a page behind (a frame replaced by
  // a newer one in its outbox) still learns that a change rebuilt something.
  std::string last_rebuilt;
  int last_rebuilt_frame = -1;
  bool problem_paused = false;  // paused by a problem, not by a page: reset goes on
  bool changed = true;  // the first step builds what the lab keeps (run.changed)
  std::string problem, problem_line;
  Eigen::Matrix3Xd shown_x = state.x;  // the newest finite positions: what every page is sent
  double energy_start = 0.0, energy_limit = 0.0, energy_now = energy_of(state);
  StrainStats strain = strain_stats(state.x, scene.springs);
  Clock::time_point next_due = Clock::now();
  auto stopping = [&] { return stop || server.stop_requested(); };  // the page's stop, Ctrl-C or SIGTERM

  auto send_error = [&](int client, const std::string& line) {
    live_log(line);  // a page that floods the run with bad messages gets its answers; stderr a summary
    server.send_text(client, live_json_text(nlohmann::json{{"type", "error"}, {"text", line}}));
  };
  auto release = [&](std::map<int, Hold>::iterator hold) {
    const int p = hold->first;
    state.inv_mass[p] = hold->second.inv_mass;
    const std::vector<Eigen::Vector3d>& trail = hold->second.trail;
    state.v.col(p).setZero();
    double held_seconds = 0.0;  // the held steps' own dt: the knob may have changed since
    for (std::size_t k = 1; k < hold->second.trail_dt.size(); ++k) held_seconds += hold->second.trail_dt[k];
    if (trail.size() >= 2 && held_seconds > 0.0) state.v.col(p) = (trail.back() - trail.front()) / held_seconds;
    holds.erase(hold);
    changed = rebase = true;
    ++version;
  };
  // The hello's fixed part (the mesh, the command), built once: a page greeted costs the knobs' JSON.
  const std::string hello_fixed = [&] {
    nlohmann::json springs = nlohmann::json::array(), rest = nlohmann::json::array();
    for (const Spring& spring : scene.springs) springs.push_back(spring.i), springs.push_back(spring.j), rest.push_back(spring.rest_length);
    nlohmann::json triangles = nlohmann::json::array();
    for (const Triangle& triangle : scene.triangles) {
      triangles.push_back(triangle.i), triangles.push_back(triangle.j), triangles.push_back(triangle.k);
    }
    std::string text = live_json_text(nlohmann::json{{"type", "hello"}, {"lab", run.lab}, {"scene", scene.name},
                                                     {"method", run.method}, {"particles", n}, {"springs", springs},
                                                     {"triangles", triangles}, {"rest_lengths", rest},
                                                     {"energy_name", run.energy_name}, {"command", command_line()},
                                                     {"colliders", nlohmann::json::parse(colliders_json(scene.colliders))}});
    text.pop_back();  // the closing brace: the knobs go after
    return text + ",\"knobs\":";
  }();
  auto hello = [&](int client) {
    greeted.insert(client);
    server.send_text(client, hello_fixed + knobs.json() + "}");
    if (!problem.empty()) {  // a page opened after the run stopped sees why (its frame follows: the last good one)
      server.send_text(client, live_json_text(nlohmann::json{{"type", "problem"}, {"frame", frame}, {"text", problem_line}}));
    }
  };

  // While the lab's step runs (stepping), what it reads (the state, the knobs, the scene) is its own: the
  // changes a page asks for then wait for its end, in order, and so do the pages that come (their hello)
  // and go; a drag's new target replaces that of the drag waiting before it (the same page, the same
  // particle), and a page has at most kWaitingPerClient changes waiting.
  bool stepping = false;
  struct Waiting {
    LiveInbound inbound;
    LiveCommand command;
  };
  std::vector<Waiting> waiting;
  auto wait_for_step = [&](const LiveInbound& inbound, const LiveCommand& command) {
    std::size_t mine = 0;
    Waiting* last = nullptr;
    for (Waiting& entry : waiting) {
      if (entry.inbound.client == inbound.client) ++mine, last = &entry;
    }
    if (last != nullptr && !last->inbound.closed && last->command.kind == LiveCommandKind::kDrag &&
        command.kind == LiveCommandKind::kDrag && last->command.particle == command.particle) {
      last->inbound.text = inbound.text;
      last->command = command;
      return;
    }
    if (mine >= kWaitingPerClient) {
      return send_error(inbound.client, "live: a step is under way and " + std::to_string(mine) +
                                            " changes of this page wait for it; this one is not made");
    }
    waiting.push_back(Waiting{inbound, command});
  };

  auto apply = [&](const LiveInbound& inbound) {
    if ((inbound.opened || inbound.closed) && stepping) {  // the hello reads the scene, which the lab's step may touch
      const auto mine = [&inbound](const Waiting& entry) { return entry.inbound.client == inbound.client; };
      const bool greeted_later = std::any_of(waiting.begin(), waiting.end(), [&](const Waiting& entry) {
        return mine(entry) && entry.inbound.opened;
      });
      if (inbound.closed && greeted_later) {  // came and went during the step: nothing of it is left to do
        waiting.erase(std::remove_if(waiting.begin(), waiting.end(), mine), waiting.end());
      } else {
        waiting.push_back(Waiting{inbound, {}});
      }
      return;
    }
    if (inbound.opened) {
      hello(inbound.client);
      return;
    }
    if (inbound.closed) {
      sent.erase(inbound.client);
      greeted.erase(inbound.client);
      for (auto hold = holds.begin(); hold != holds.end();) {
        auto next = std::next(hold);
        if (hold->second.client == inbound.client) release(hold);
        hold = next;
      }
      return;
    }
    const LiveParse parse = parse_live_message(inbound.text, knobs, n);
    if (!parse.ok()) return send_error(inbound.client, parse.error);
    const LiveCommand& command = parse.command;
    const LiveCommandKind kind = command.kind;
    if (stepping && (kind == LiveCommandKind::kReset || kind == LiveCommandKind::kSet || kind == LiveCommandKind::kDrag ||
                     kind == LiveCommandKind::kRelease || kind == LiveCommandKind::kPin)) {
      return wait_for_step(inbound, command);
    }
    const int p = command.particle;
    switch (command.kind) {
      case LiveCommandKind::kPause: paused = true; break;
      case LiveCommandKind::kResume:
      case LiveCommandKind::kStep:
        if (!problem.empty()) return send_error(inbound.client, "live: the run stopped at frame " + std::to_string(frame) + ": reset it first");
        if (command.kind == LiveCommandKind::kStep) step_once = paused = true;
        else paused = false, next_due = Clock::now();
        break;
      case LiveCommandKind::kReset:
        state = start;
        shown_x = state.x;
        holds.clear();
        if (problem_paused) paused = false, next_due = Clock::now();  // "paused; reset to go on"
        problem_paused = false;
        problem.clear();
        energy_noted = false;
        frame = 0, time = 0.0;
        changed = rebase = true;
        break;
      case LiveCommandKind::kStop: stop = true; break;
      case LiveCommandKind::kAck: server.acknowledge(inbound.client); return;
      case LiveCommandKind::kSpeed: speed = command.value; break;
      case LiveCommandKind::kSet:
        knobs.set(static_cast<std::size_t>(command.knob), command.value);
        changed = rebase = true;
        break;
      case LiveCommandKind::kDrag: {
        auto hold = holds.find(p);
        if (hold != holds.end() && hold->second.client != inbound.client) {
          return send_error(inbound.client, "live: drag: particle " + std::to_string(p) + " is held by another page");
        }
        if (hold == holds.end()) {
          if (state.inv_mass[p] <= 0.0) {
            return send_error(inbound.client, "live: drag: particle " + std::to_string(p) + " is pinned (unpin it first)");
          }
          for (auto other = holds.begin(); other != holds.end();) {  // one particle per page at a time
            auto next = std::next(other);
            if (other->second.client == inbound.client) release(other);
            other = next;
          }
          hold = holds.emplace(p, Hold{inbound.client, state.inv_mass[p], command.target, {}, {}}).first;
          state.inv_mass[p] = 0.0;
          changed = true;
        }
        hold->second.target = command.target;
        state.x.col(p) = command.target;
        state.v.col(p).setZero();
        break;
      }
      case LiveCommandKind::kRelease: {
        const auto hold = holds.find(p);
        if (hold == holds.end() || hold->second.client != inbound.client) {
          return send_error(inbound.client, "live: release: particle " + std::to_string(p) + " is not held by this page");
        }
        release(hold);
        break;
      }
      case LiveCommandKind::kPin:
        if (holds.count(p)) return send_error(inbound.client, "live: pin: particle " + std::to_string(p) + " is held (release it first)");
        state.inv_mass[p] = state.inv_mass[p] > 0.0 ? 0.0 : (start.inv_mass[p] > 0.0 ? start.inv_mass[p] : free_inv_mass);
        state.v.col(p).setZero();
        changed = rebase = true;
        break;
    }
    ++version;
  };

  auto take_messages = [&] {
    for (const LiveInbound& inbound : server.take_inbound()) {  // a bounded number a turn
      if (stopping()) return;
      try {
        apply(inbound);
      } catch (const std::exception& error) {  // one message's failure is its page's error, never the run's end
        send_error(inbound.client, std::string("live: a message could not be handled: ") + error.what());
      }
    }
  };

  // The end of the run: its line on stdout, the summary of `final_state`.
  auto end_run = [&](Particles& final_state) {
    live_log_flush(true);
    for (auto& [p, hold] : holds) final_state.inv_mass[p] = hold.inv_mass;
    std::printf("%s: live run ended after %d frames (%.3g s of simulated time, %.3e s per frame)\n", run.lab.c_str(),
                steps_done, time, steps_done > 0 ? seconds / steps_done : 0.0);
    if (!summary_path.empty()) {
      RunSummary summary = stepping_summary(run.lab, run.method, scene, final_state, strain, seconds);
      summary.steps = steps_done;
      summary.dt = dt_now();
      summary.extra["live"] = true;
      summary.extra["frames"] = frame;
      nlohmann::ordered_json values = nlohmann::ordered_json::object();
      for (const Knob& knob : knobs.all()) values[knob.name] = knob.value;
      summary.extra["knobs"] = values;
      summary.extra["problem"] = problem;
      write_summary(summary_path, summary);
    }
  };

  StepThread stepper;
  Particles before = state;  // the state before the step under way: the summary's, should a stop end it
  auto step = [&] {
    const bool rebuild = changed && run.changed;
    changed = false;
    before = state;
    double change_seconds = 0.0, step_seconds = 0.0;
    StepVerdict verdict;
    std::string job_rebuilt;
    stepper.start([&] {
      const Timer change_timer;
      if (rebuild) job_rebuilt = run.changed(knobs);
      change_seconds = change_timer.seconds();  // a refactorization: the page says this step cost more
      const Timer timer;
      verdict = run.step(knobs);
      step_seconds = timer.seconds();
    });
    stepping = true;
    const Timer under_way;
    double stop_seen = -1.0;  // when a stop came, s into the step
    while (!stepper.wait(0.02)) {  // the step goes on: the loop takes messages and watches for a stop
      take_messages();
      live_log_flush();
      if (stopping() && stop_seen < 0.0) stop_seen = under_way.seconds();
      if (stop_seen >= 0.0 && under_way.seconds() > stop_seen + kStopGraceSeconds) {
        // The step cannot be interrupted (it is the lab's code) and the run does not wait for it: the
        // summary is of the last completed step, and the process ends here, the step's thread with it.
        live_log("live: stopped during the step after frame " + std::to_string(frame) + " (under way for " +
                 std::to_string(int(under_way.seconds())) + " s): the run ends without it");
        try {
          end_run(before);
        } catch (const std::exception& error) {
          std::fprintf(stderr, "%s: error: %s\n", run.lab.c_str(), error.what());
          std::fflush(stdout);
          std::fflush(stderr);
          std::_Exit(2);
        }
        std::fflush(stdout);
        std::fflush(stderr);
        std::_Exit(0);
      }
    }
    stepping = false;
    rebuilt = job_rebuilt;
    stepped_with = knobs;
    for (auto& [p, hold] : holds) {  // a held particle is where the page holds it, whatever the step did
      state.x.col(p) = hold.target;
      state.v.col(p).setZero();
      hold.trail.push_back(hold.target);
      hold.trail_dt.push_back(dt_now());
      if (hold.trail.size() > kTrail) hold.trail.erase(hold.trail.begin()), hold.trail_dt.erase(hold.trail_dt.begin());
    }
    previous_step_seconds = last_step_seconds;
    last_step_seconds = (verdict.seconds >= 0.0 ? verdict.seconds : step_seconds) + change_seconds;
    seconds += last_step_seconds;
    if (verdict.taken) ++frame, ++steps_done, time += dt_now();
    if (!rebuilt.empty()) last_rebuilt = rebuilt, last_rebuilt_frame = frame;
    strain = strain_stats(state.x, scene.springs);
    energy_now = energy_of(state);
    problem = verdict.problem;
    if (problem.empty()) problem = health_problem(state, strain);
    if (problem.empty() && rebase) {
      energy_start = energy_now;
      energy_limit = energy_scale(state, scene.gravity, dt_now());
      rebase = false;
    } else if (problem.empty() && holds.empty()) {
      const std::string rose = energy_rise_problem(energy_now - energy_start, energy_limit, run.energy_name);
      if (run.energy_stops) {
        problem = rose;
      } else if (!rose.empty() && !energy_noted) {
        energy_noted = true;  // once per run (and again after a reset)
        send_error(-1, "live: frame " + std::to_string(frame) + ": " + rose + " (reported; the run goes on)");
      }
    }
    if (state.x.allFinite()) shown_x = state.x;
    if (!problem.empty()) {
      paused = problem_paused = true;
      problem_line = "live: frame " + std::to_string(frame) + ": " + problem + " (paused; reset to go on)";
      live_log(problem_line);
      server.send_text(-1, live_json_text(nlohmann::json{{"type", "problem"}, {"frame", frame}, {"text", problem_line}}));
    }
    ++version;
    for (Waiting& entry : std::exchange(waiting, {})) {  // the changes asked for while it ran, in order
      try {
        apply(entry.inbound);
      } catch (const std::exception& error) {
        send_error(entry.inbound.client, std::string("live: a message could not be handled: ") + error.what());
      }
    }
  };

  // A frame with a non-finite value is never sent: every page gets the last good positions (and a page
  // that connects after a problem gets them too, with the problem in the status).
  auto send_frames = [&] {
    std::vector<float> data;
    std::string status;
    for (const int client : server.ready_clients()) {
      if (!greeted.count(client) || (sent.count(client) && sent[client] == version)) continue;
      if (data.empty()) {
        const std::size_t m = scene.springs.size();
        data.reserve(3 * static_cast<std::size_t>(n) + m);
        for (Eigen::Index p = 0; p < n; ++p) {
          for (int a = 0; a < 3; ++a) data.push_back(static_cast<float>(shown_x(a, p)));
        }
        for (const Spring& spring : scene.springs) data.push_back(static_cast<float>(signed_strain(shown_x, spring)));
        nlohmann::json values = nlohmann::json::object(), pinned = nlohmann::json::array(), held = nlohmann::json::array();
        nlohmann::json used = nlohmann::json::object();
        for (const Knob& knob : knobs.all()) values[knob.name] = knob.value;
        for (const Knob& knob : stepped_with.all()) used[knob.name] = knob.value;
        for (Eigen::Index p = 0; p < n; ++p) {
          if (state.inv_mass[p] <= 0.0 && !holds.count(static_cast<int>(p))) pinned.push_back(p);
        }
        for (const auto& [p, hold] : holds) {
          held.push_back({{"particle", p}, {"x", {state.x(0, p), state.x(1, p), state.x(2, p)}}});
        }
        const double shown_energy = std::isfinite(energy_now) ? energy_now : 0.0;
        status = live_json_text(nlohmann::json{{"type", "frame"}, {"frame", frame}, {"time", time}, {"step_seconds", last_step_seconds},
                                {"previous_step_seconds", previous_step_seconds}, {"refactored", !rebuilt.empty()}, {"rebuilt", rebuilt},
                                {"last_rebuilt", last_rebuilt}, {"last_rebuilt_frame", last_rebuilt_frame},
                                {"max_strain", std::isfinite(strain.max) ? strain.max : 0.0}, {"energy", shown_energy},
                                {"paused", paused}, {"speed", speed}, {"knobs", values}, {"step_knobs", used}, {"pinned", pinned},
                                {"held", held}, {"problem", problem}, {"clients", server.clients()}});
      }
      server.send_frame(client, status, data);
      sent[client] = version;
    }
  };

  while (!stopping()) {
    take_messages();
    if (stopping()) break;
    const Clock::time_point now = Clock::now();
    if (step_once || (!paused && problem.empty() && now >= next_due)) {
      step_once = false;
      rebuilt.clear();
      step();
      const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(dt_now() / speed));
      next_due += period;
      if (next_due < Clock::now() - std::chrono::milliseconds(100)) next_due = Clock::now();
    }
    send_frames();
    live_log_flush();
    const double wait = paused ? 0.05 : std::chrono::duration<double>(next_due - Clock::now()).count();
    server.wait_inbound(std::min(std::max(wait, 0.0), 0.05));
  }
  end_run(state);
  return 0;
}

}  // namespace cl
