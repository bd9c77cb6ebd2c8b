// ambfplus/engine: RealTimeLoop, which steps a world in real time (the engine's Simulator is
// made in py_scene.cpp, where Simulator is bound, by engine::create_simulator).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "ambfplus/engine/realtime.h"
#include "ambfplus/plugin/registry.h"
#include "ambfplus/scene/world.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

// The loops Python made, so that interpreter exit stops those still running (a loop's threads
// running on while the interpreter and the engine's statics go away ended in SIGABRT).
std::mutex& loops_mutex() {
  static std::mutex m;
  return m;
}
std::set<RealTimeLoop*>& loops() {
  static std::set<RealTimeLoop*> all;
  return all;
}

void start_loop(RealTimeLoop& loop) {
  {
    std::lock_guard<std::mutex> lock(loops_mutex());
    loops().insert(&loop);
  }
  py::gil_scoped_release release;
  loop.start();
}

// At exit (Python's atexit, before the interpreter finalizes): stops every running loop.
void stop_loops_at_exit() {
  std::vector<RealTimeLoop*> running;
  {
    std::lock_guard<std::mutex> lock(loops_mutex());
    running.assign(loops().begin(), loops().end());
  }
  py::gil_scoped_release release;
  for (RealTimeLoop* loop : running) {
    try {
      loop->stop();
    } catch (const std::exception&) {
      // An error that stopped a step: at exit there is nobody left to raise it to.
    }
  }
}

// Destroys a loop with the GIL released: its polling thread may be waiting for the GIL.
struct ReleaseGilDelete {
  void operator()(RealTimeLoop* loop) const {
    {
      std::lock_guard<std::mutex> lock(loops_mutex());
      loops().erase(loop);
    }
    py::gil_scoped_release release;
    delete loop;
  }
};
using LoopHolder = std::unique_ptr<RealTimeLoop, ReleaseGilDelete>;

py::dict stats_dict(const RealTimeStats& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["seconds"] = s.seconds;
  d["mean_rate"] = s.mean_rate;
  d["p99"] = s.p99;
  d["max"] = s.max;
  d["over_2ms"] = s.over_2ms;
  d["step_cpu_p99"] = s.step_p99;
  d["step_cpu_max"] = s.step_cpu_max;
  d["step_wall_max"] = s.step_wall_max;
  d["lock_wait_max"] = s.lock_wait_max;
  d["lock_wait_p99"] = s.lock_wait_p99;
  d["late"] = s.late;
  d["late_step_wall"] = s.late_step_wall;
  d["late_step_cpu"] = s.late_step_cpu;
  d["periods"] = py::array_t<double>(static_cast<py::ssize_t>(s.periods.size()), s.periods.data());
  return d;
}

}  // namespace

void declare_engine(py::module_& m) {
  py::class_<RealTimeLoop, LoopHolder>(
      m, "RealTimeLoop",
      "Steps a world in real time on its own thread (1 kHz by default, absolute deadlines, "
      "SCHED_FIFO where allowed), while other threads capture. Use as a context manager, or "
      "start()/stop(). Change the world from Python only inside `with loop.lock():`.");
}

void define_engine(py::module_& m) {
  py::module_::import("atexit").attr("register")(py::cpp_function(&stop_loops_at_exit));
  bound<RealTimeLoop, LoopHolder>(m, "RealTimeLoop")
      .def(py::init([](std::shared_ptr<World> world, double rate, int fifo_priority, int cpu,
                       double poll_rate) {
             RealTimeOptions o;
             o.rate = rate;
             o.fifo_priority = fifo_priority;
             o.cpu = cpu;
             o.poll_rate = poll_rate;
             LoopHolder loop(new RealTimeLoop(*world, o));
             World* w = world.get();
             // Python plugins get their physics update on the low-rate thread, under the
             // world's lock taken while holding the GIL (see lock_holding_gil).
             loop->set_poll_hook([w](double dt) {
               if (dt <= 0) return;
               {
                 auto lock = w->lock_state_for_copy();
                 if (!plugins_of(*w).has_foreign()) return;
               }
               py::gil_scoped_acquire gil;
               auto lock = lock_holding_gil(*w);
               plugins_of(*w).foreign_physics_update(dt);
             });
             return loop;
           }),
           py::arg("world"), py::arg("rate") = 1000.0, py::arg("fifo_priority") = 80,
           py::arg("cpu") = -1, py::arg("poll_rate") = 100.0, py::keep_alive<1, 2>(),
           "rate: steps per second; fifo_priority: SCHED_FIFO priority to ask for (0: none); "
           "cpu: pin to this CPU (-1: the last, only if SCHED_FIFO is refused; -2: never); "
           "poll_rate: Hz of the thread serving Python devices and plugins.")
      .def("start", &start_loop, "Starts stepping (interpreter exit stops it).")
      .def(
          "stop",
          [](RealTimeLoop& l) {
            py::gil_scoped_release release;
            l.stop();
          },
          "Stops after the step in progress; re-raises an error that stopped a step.")
      .def_property_readonly("running", &RealTimeLoop::running)
      .def_property_readonly("scheduling", &RealTimeLoop::scheduling,
                             "how the loop's thread is scheduled (SCHED_FIFO, or what it fell "
                             "back to and why)")
      .def_property_readonly(
          "stats", [](RealTimeLoop& l) { return stats_dict(l.stats()); },
          "steps, seconds, mean_rate (Hz), p99 and max period (s), over_2ms (count), "
          "step_cpu_p99 (s), lock waits (s), periods (array, s)")
      .def(
          "lock", [](RealTimeLoop& l) { return state_lock(l.world()); },
          "A context manager holding the world's state lock (the loop waits meanwhile).")
      .def(
          "__enter__",
          [](RealTimeLoop& l) -> RealTimeLoop& {
            start_loop(l);
            return l;
          },
          py::return_value_policy::reference, "Starts stepping.")
      .def(
          "__exit__",
          [](RealTimeLoop& l, py::args) {
            py::gil_scoped_release release;
            l.stop();
            return false;
          },
          "Stops stepping.");
}

}  // namespace ambfplus::bindings
