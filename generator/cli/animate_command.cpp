// `hamel animate MODEL -o FILE.html (--t-end T ... | --path "r1(t);..." --period T --cycles N)`: one self-contained
// HTML page that plays the model's motion in 3-D (report/animation_page.hpp). The motion is simulate's (its options,
// integrators and CSV, with rkmk4 on bundle models for the group element g(t)) or phase's (the base motion along a
// closed shape path); every body's pose at each sample comes from the model's own kinematics (numeric/body_poses.hpp)
// and is drawn as the box of equal inertia about its centre of mass. See docs/animate.md.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "cli/simulation.hpp"
#include "model/input_error.hpp"
#include "numeric/body_poses.hpp"
#include "numeric/phase.hpp"
#include "report/animation_page.hpp"
#include "report/atomic_file.hpp"
#include "report/progress.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace hamel::cli {

namespace {

struct AnimateOptions {
  SimulateOptions sim;
  std::function<void()> sim_given;
  std::string path, momentum = "zero", out, up;
  double period = 1;
  int cycles = 1, steps = 2000, samples = 100;
  bool path_given = false, phase_option_given = false;
};

// Samples of a motion: times, the model's coordinates at each, and the group frame (floating bases).
struct Motion {
  std::vector<double> t;
  std::vector<std::vector<double>> q;  // model.coordinates order
  std::vector<Placement> base;         // empty: no group frame
};

Placement placement_of(const GroupPose& g, const std::string& group) {
  Placement out;
  if (g.R) out.R = *g.R;
  if (g.theta) {
    const double c = std::cos(*g.theta), s = std::sin(*g.theta);
    out.R = {c, -s, 0, s, c, 0, 0, 0, 1};
  }
  if (g.p.size() > 3)
    throw InputError("hamel animate draws motion in 3-D: the group " + group + " has " + std::to_string(g.p.size()) +
                     " translations; expected SO3, SE3, SO3xR3, SE2 or R1-R3");
  for (std::size_t k = 0; k < g.p.size(); ++k) out.p[k] = g.p[k];
  return out;
}

// The CSV `hamel simulate` wrote, read back by column name.
Motion motion_from_csv(const std::string& text, const Model& model) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::size_t> column;
  {
    std::istringstream header(line);
    std::string name;
    for (std::size_t k = 0; std::getline(header, name, ','); ++k) column[name] = k;
  }
  std::vector<std::size_t> q_columns;
  for (const auto& q : model.coordinates) q_columns.push_back(column.at(q.get_name()));
  std::vector<std::string> pose_names;
  if (model.bundle) {
    const GroupPose sample = with_group(model.bundle->group, [](auto tag) {
      using G = typename decltype(tag)::type;
      return pose_of(0.0, G::identity());
    });
    pose_names = pose_columns(sample);
  }
  for (const std::string& name : pose_names)
    if (!column.count(name))
      throw std::logic_error("hamel animate: the simulation wrote no group element (column " + name + ")");
  Motion m;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    m.t.push_back(row.at(0));
    std::vector<double> q;
    for (std::size_t c : q_columns) q.push_back(row.at(c));
    m.q.push_back(q);
    if (!pose_names.empty()) {
      GroupPose g;
      if (column.count("R00")) {
        std::array<double, 9> R{};
        for (std::size_t k = 0; k < 9; ++k) R[k] = row.at(column.at(pose_names[k]));
        g.R = R;
      }
      if (column.count("theta")) g.theta = row.at(column.at("theta"));
      for (const std::string& name : pose_names)
        if (name[0] != 'R' && name != "theta") g.p.push_back(row.at(column.at(name)));
      m.base.push_back(placement_of(g, model.bundle->group));
    }
  }
  return m;
}

Motion simulated_motion(AnimateOptions& opt, Pipeline& pipeline) {
  SimulateOptions sim = opt.sim;
  const Model& model = pipeline.model();
  if (model.bundle) {
    const auto& scene = pipeline.target().scene;
    if (sim.integrator.empty()) {
      sim.integrator = "rkmk4";
      if (scene && !scene->integrator.empty() && scene->integrator != "rkmk4")
        std::cerr << "hamel: note: the scene integrates with " << scene->integrator
                  << "; hamel animate takes rkmk4, which reconstructs the group element g(t) the page needs (step "
                     "--dt, default 1e-3)\n";
    }
    if (sim.integrator != "rkmk4")
      throw InputError("--integrator: hamel animate needs the group element g(t) of bundle model " + quote(model.name) +
                       ", which rkmk4 reconstructs; got " + quote(sim.integrator) +
                       ", expected rkmk4 (the default for bundle models)");
  }
  sim.out = opt.out;
  sim.monitors.clear();
  const double t_end = sim.t_end > 0                                               ? sim.t_end
                       : pipeline.target().scene && pipeline.target().scene->t_end ? *pipeline.target().scene->t_end
                                                                                   : 0;
  if (!sim.sample_given && t_end > 0) sim.sample = t_end / 250;  // 250 frames: smooth, and the page stays small
  std::ostringstream csv;
  if (t_end > 0) {
    std::ostringstream what;
    what << "integrating " << model.name << " to t = " << t_end;
    progress::say(what.str());
  }
  simulate(
      sim, pipeline, [&]() -> std::ostream& { return csv; }, [] {}, [] {});
  return motion_from_csv(csv.str(), model);
}

Motion phase_motion(const AnimateOptions& opt, Pipeline& pipeline) {
  if (opt.momentum != "zero" && opt.momentum != "rest")
    throw InputError("--momentum: expected zero or rest, got '" + opt.momentum + "'");
  const Model& model = pipeline.model();
  if (!model.bundle)
    throw InputError(opt.sim.in.file + ": --path (a phase experiment) needs a bundle model (with 'group' and 'shape')");
  PhaseRequest req;
  req.path = parse_path(opt.path, model);
  req.period = opt.period;
  req.cycles = opt.cycles;
  req.momentum = opt.momentum == "rest" ? PhaseMomentum::rest : PhaseMomentum::zero;
  req.steps_per_cycle = opt.steps;
  req.samples_per_cycle = opt.samples;
  check_phase_request(model, req);
  pipeline.settings().form = phase_form(model);
  const Derivation& d = pipeline.derivation();
  progress::say("reconstructing " + std::to_string(opt.cycles) + " cycle(s) on " + model.bundle->group);
  const PhaseResult result = compute_phase(model, d, pipeline.parameters(), req);
  GiNaC::exmap at;
  for (std::size_t k = 0; k < model.parameters.size(); ++k) at[model.parameters[k].symbol] = pipeline.parameters()[k];
  Motion m;
  for (const GroupPose& g : result.trajectory) {
    m.t.push_back(g.t);
    at[model.time] = g.t;
    std::vector<double> q;
    for (const GiNaC::ex& r : req.path) q.push_back(GiNaC::ex_to<GiNaC::numeric>(r.subs(at).evalf()).to_double());
    m.q.push_back(q);
    m.base.push_back(placement_of(g, model.bundle->group));
  }
  return m;
}

std::array<double, 3> up_direction(const AnimateOptions& opt, const Model& model, const std::vector<double>& p) {
  if (!opt.up.empty()) {
    const std::vector<std::string> items = split_list(opt.up);
    std::array<double, 3> u{};
    bool ok = items.size() == 3;
    for (std::size_t k = 0; ok && k < 3; ++k) {
      try {
        std::size_t used = 0;
        u[k] = std::stod(items[k], &used);
        ok = used == items[k].size() && std::isfinite(u[k]);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || u[0] * u[0] + u[1] * u[1] + u[2] * u[2] == 0)
      throw InputError("--up: expected three numbers x,y,z of a non-zero vector, got " + quote(opt.up));
    return u;
  }
  const KinematicTree* tree = model.tree                           ? &*model.tree
                              : model.bundle && model.bundle->tree ? &*model.bundle->tree
                              : model.closed_tree                  ? &*model.closed_tree
                                                                   : nullptr;
  if (tree && tree->has_gravity()) {
    GiNaC::exmap at;
    for (std::size_t k = 0; k < model.parameters.size(); ++k) at[model.parameters[k].symbol] = p[k];
    std::array<double, 3> u{};
    for (int k = 0; k < 3; ++k) {
      const GiNaC::ex g = tree->gravity[k].subs(at).evalf();
      if (!GiNaC::is_a<GiNaC::numeric>(g)) return {0, 0, 1};
      u[static_cast<std::size_t>(k)] = -GiNaC::ex_to<GiNaC::numeric>(g).to_double();
    }
    return u;
  }
  return {0, 0, 1};
}

void run(AnimateOptions& opt) {
  opt.sim_given();
  if (opt.out.empty()) throw InputError("--out: expected the HTML file to write (-o FILE.html)");
  if (opt.path_given &&
      (opt.sim.t_end != 0 || !opt.sim.integrator.empty() || opt.sim.dt_given || opt.sim.tol_given ||
       !opt.sim.init.empty() || !opt.sim.inputs.empty() || !opt.sim.input_file.empty() || opt.sim.sample_given))
    throw InputError(
        "--path: a phase experiment prescribes the shape and takes --period, --cycles, --momentum, "
        "--steps-per-cycle and --samples-per-cycle; expected either --path or simulate's options (--t-end, "
        "--integrator, --dt, --tol, --init, --input, --input-file, --sample), not both");
  if (!opt.path_given && opt.phase_option_given)
    throw InputError("--period, --cycles, --momentum, --steps-per-cycle and --samples-per-cycle go with --path");
  if (!animation_pages_available()) throw RunFailed(missing_three_js());
  Pipeline pipeline(opt.sim.in);
  const Model& model = pipeline.model();
  const BodyPoses poses(model, pipeline.parameters());
  if (poses.bodies().empty() && !model.bundle)
    throw InputError(SourceLocation{model.source_path, 0, 0}, "bodies",
                     "model " + quote(model.name) +
                         " does not say where its bodies are (it gives its Lagrangian, not 'bodies' or 'tree'); "
                         "expected a model with 'bodies' (each with position and rotation) or a kinematic 'tree', "
                         "or a bundle model, whose group frame is drawn");
  const std::array<double, 3> up = up_direction(opt, model, pipeline.parameters());
  const Motion motion = opt.path_given ? phase_motion(opt, pipeline) : simulated_motion(opt, pipeline);

  Animation a;
  a.title = model.name + (opt.path_given ? ": phase experiment, momentum " + opt.momentum : ": simulated motion");
  a.up = up;
  // Massless bodies (a fixed base's world) are not drawn; slender and flat boxes are thickened to a tenth of their
  // largest edge, point masses to a box of a twentieth of the largest body's, so that each stays visible.
  std::vector<std::size_t> drawn;
  std::vector<InertiaBox> boxes;
  double largest = 0;
  for (const BodyInertiaValues& b : poses.bodies()) {
    boxes.push_back(inertia_box(b));
    largest = std::max(largest, *std::max_element(boxes.back().edges.begin(), boxes.back().edges.end()));
  }
  bool thickened = false;
  for (std::size_t i = 0; i < poses.bodies().size(); ++i) {
    if (!(poses.bodies()[i].mass > 0)) continue;
    drawn.push_back(i);
    std::array<double, 3> e = boxes[i].edges;
    const double own = *std::max_element(e.begin(), e.end());
    const double floor = own > 0 ? 0.1 * own : largest > 0 ? 0.05 * largest : 0.05;
    for (double& edge : e)
      if (edge < floor) edge = floor, thickened = true;
    a.bodies.push_back({poses.bodies()[i].name, e});
  }
  a.times = motion.t;
  for (std::size_t k = 0; k < motion.t.size(); ++k) {
    const Placement base = motion.base.empty() ? Placement{} : motion.base[k];
    const std::vector<Placement> world = poses.at(motion.t[k], motion.q[k], base);
    std::vector<BoxPose> frame;
    for (std::size_t i : drawn) {
      const Placement box = compose(world[i], boxes[i].in_body);
      const std::array<double, 4> q = quaternion_of(box.R);
      frame.push_back({box.p[0], box.p[1], box.p[2], q[0], q[1], q[2], q[3]});
    }
    a.poses.push_back(frame);
    if (!motion.base.empty()) {
      const std::array<double, 4> q = quaternion_of(base.R);
      a.base.push_back({base.p[0], base.p[1], base.p[2], q[0], q[1], q[2], q[3]});
    }
  }
  if (model.bundle) a.base_name = model.bundle->group + " frame";
  a.notes.push_back("Each body is the box of equal mass and inertia about its centre of mass" +
                    std::string(thickened ? " (slender or flat ones thickened to stay visible)" : "") + ".");
  if (!motion.base.empty()) a.notes.push_back("The red line is the path of the group frame's origin.");
  if (model.bundle && !model.bundle->tree)
    a.notes.push_back(
        "This model gives its kinetic energy by twists or as an expression, not where its bodies are: "
        "only the group frame is drawn.");
  if (model.bundle && !model.bundle->tree)
    std::cerr << "hamel: note: " << model.name
              << " gives its bodies by their twists (or T as an expression), not by their placements: the page draws "
                 "the group frame and its path only (a kinematic tree, key 'tree', says where every body is)\n";
  // Opened once the run's inputs are read (the page may not replace one of them), written whole or not at all.
  OutputTransaction output;
  output.open(opt.out, "--out") << render_animation_page(a);
  output.commit();
  std::cerr << "hamel: wrote " << opt.out << ": " << a.bodies.size() << " bodies, " << a.times.size()
            << " frames from t = " << a.times.front() << " to " << a.times.back() << "\n";
}

}  // namespace

Run add_animate_command(CLI::App& app) {
  auto opt = std::make_shared<AnimateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "animate",
      "Write one self-contained HTML page (three.js inlined, works offline) that plays the model's motion in 3-D: "
      "a simulation (simulate's options) or a phase experiment (--path); bodies drawn as boxes of equal inertia");
  add_pipeline_options(cmd, opt->sim.in);
  cmd->add_option("-o,--out", opt->out, "The HTML file to write")->required();
  opt->sim_given = add_simulate_options(cmd, opt->sim);
  cmd->get_option("--sample")->description("Interval between frames (default t_end/250)");
  CLI::Option* path = cmd->add_option(
      "--path", opt->path,
      "A phase experiment instead of a simulation (bundle models, as hamel phase): the shape path r(t), one "
      "expression in t per shape coordinate, separated by ';'");
  std::vector<CLI::Option*> phase_options = {
      cmd->add_option("--period", opt->period, "With --path: period T of the path [s]")->capture_default_str(),
      cmd->add_option("--cycles", opt->cycles, "With --path: number of cycles N")->capture_default_str(),
      cmd->add_option("--momentum", opt->momentum,
                      "With --path: zero (geometric phase) or rest (base at rest at t = 0)")
          ->capture_default_str(),
      cmd->add_option("--steps-per-cycle", opt->steps, "With --path: RKMK4 steps per cycle")->capture_default_str(),
      cmd->add_option("--samples-per-cycle", opt->samples, "With --path: frames per cycle")->capture_default_str()};
  cmd->add_option("--up", opt->up,
                  "The world direction drawn upward, x,y,z (default: against a tree's gravity, else 0,0,1)");
  cmd->footer(
      "Simulations default to 250 frames (--sample t_end/250) and, for bundle models, --integrator rkmk4 (the "
      "page needs the group element g(t)). Open the page with #t=<time> to stop at that time: <pre id=\"probe\"> then "
      "lists every body's position as three.js places it. Examples:\n"
      "  hamel animate models/four_bar_tree.yaml --t-end 2 -o four_bar.html\n"
      "  hamel animate models/satellite_se3_tree.yaml --path \"pi*(cos(2*pi*t) - 1); pi*sin(2*pi*t); "
      "pi/2*sin(4*pi*t)\" --cycles 6 -o satellite.html");
  return [opt, path, phase_options] {
    opt->path_given = path->count() > 0;
    for (CLI::Option* o : phase_options) opt->phase_option_given = opt->phase_option_given || o->count() > 0;
    run(*opt);
  };
}

}  // namespace hamel::cli
