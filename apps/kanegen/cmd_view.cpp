// kanegen view MODEL [RUN.csv] [--frames N] [--columns a,b] -o VIEW.html: a self-contained 3D view of a model
// (its initial state) or of a run (issue 37; view/view_data.hpp, view/view_page.hpp): bodies as the boxes of
// their mass properties, joints with their axes, flexible bodies' nodes, a time slider, play, events and
// chosen columns plotted. One HTML file that opens offline in any current browser.
#include <fmt/format.h>

#include "apps/kanegen/cli_common.hpp"
#include "engine/load_model.hpp"
#include "model/diagnostics.hpp"
#include "model/model_files.hpp"
#include "model/output_file.hpp"
#include "view/run_table.hpp"
#include "view/view_data.hpp"
#include "view/view_page.hpp"

namespace kanegen::cli {

namespace view_command {

struct Options {
  std::string model, run, output, events;
  int frames = 500;
  std::vector<std::string> columns;
};

int run(const Options& o) {
  const Model model = load_model(o.model);
  std::vector<std::string> inputs = model_files(model);
  if (!o.run.empty()) inputs.push_back(o.run);
  if (!o.events.empty()) inputs.push_back(o.events);
  if (!o.events.empty() && o.run.empty())
    throw InputError(Diagnostic{o.events, 0, "--events", "an events table without its run's CSV"});
  check_output_options({{"-o", o.output}}, inputs);
  if (o.frames < 1)
    throw InputError(Diagnostic{o.model, 0, "--frames", fmt::format("{}; expected at least 1 frame", o.frames)});
  std::optional<RunTable> table;
  if (!o.run.empty()) table = read_run_table(o.run);
  std::vector<RunEvent> events;
  if (!o.events.empty()) events = read_events_table(o.events);
  ViewOptions vo;
  vo.frames = o.frames;
  vo.columns = o.columns;
  if (!o.events.empty()) vo.events = &events;
  const nlohmann::json data = view_data(model, table ? &*table : nullptr, vo, o.events);
  const std::string page = view_page(data);
  write_file_atomically(o.output, page);
  fmt::print("{}: {} bodies, {} frames{} ({:.2f} MB); open it in a browser (offline)\n", o.output, model.bodies.size(),
             data["t"].size(),
             table ? fmt::format(" of {} rows from t = {:g} to {:g} s", table->rows.rows(), table->rows(0, 0),
                                 table->rows(table->rows.rows() - 1, 0))
                   : std::string(" (the initial state)"),
             page.size() / 1e6);
  return 0;
}

}  // namespace view_command

Subcommand add_view(CLI::App& app) {
  auto o = std::make_shared<view_command::Options>();
  CLI::App* c = app.add_subcommand(
      "view", "a self-contained 3D view (one HTML file, offline) of a model, or of a run of it: bodies, joints, "
              "flexible nodes, a time slider, events and chosen columns");
  add_model_option(c, o->model);
  c->add_option("run", o->run, "a CSV written by kanegen simulate for this model (without: the initial state)")
      ->check(CLI::ExistingFile);
  c->add_option("--frames", o->frames, "most frames kept from the run (evenly in time; both rows of every event)")
      ->capture_default_str();
  c->add_option("--columns", o->columns, "run columns plotted beside the view (default: T, V and the root's rates)")
      ->delimiter(',');
  c->add_option("--events", o->events,
                "the run's events table (kanegen simulate --events): events named on the timeline, locked joints "
                "marked frame by frame")
      ->check(CLI::ExistingFile);
  c->add_option("-o,--output", o->output, "output VIEW.html")->required();
  return {c, [o] { return view_command::run(*o); }};
}

}  // namespace kanegen::cli
