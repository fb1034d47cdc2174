// kanegen generate MODEL -o OUT.hpp [--entry E.cpp] [--manifest M.json] [--depfile D]:
// the model's specialized header, and on request its C entry file and
// manifest (what kanegen_add_model() builds an ahead-of-time simulator from).
#include <fmt/format.h>

#include <filesystem>

#include "apps/kanegen/cli_common.hpp"
#include "codegen/assembler.hpp"
#include "codegen/generator.hpp"
#include "engine/resources.hpp"
#include "model/model_files.hpp"
#include "model/output_file.hpp"

namespace kanegen::cli {

namespace generate_command {

struct Options {
  std::string model, output, entry, manifest, depfile, form = "auto", code = "auto";
};

int run(const Options& o) {
  // Every output is checked before any work (and against the files the
  // model is read from), so that a bad path is refused up front and nothing
  // is half-written.
  const Model model = load_checked(o.model);
  std::vector<OutputOption> outputs{{"-o", o.output}};
  const std::pair<const char*, const std::string*> optional[] = {
      {"--entry", &o.entry}, {"--manifest", &o.manifest}, {"--depfile", &o.depfile}};
  for (const auto& [option, path] : optional)
    if (!path->empty()) outputs.push_back({option, *path});
  check_output_options(outputs, model_files(model));
  codegen::GeneratorOptions opt;
  opt.udot_form = o.form;
  opt.udot_code = o.code;
  const codegen::EmittedModel emitted = codegen::generate(model, opt);
  // The entry file includes the header by its file name: both go in one directory.
  const std::string header_name = std::filesystem::path(o.output).filename().string();
  const codegen::AssembledFiles files = codegen::assemble(emitted, template_dir(), header_name);
  write_file_atomically(o.output, files.header);
  if (!o.entry.empty()) write_file_atomically(o.entry, files.entry);
  if (!o.manifest.empty()) write_file_atomically(o.manifest, files.manifest);
  if (!o.depfile.empty()) {  // Make-style: the outputs depend on the model and its modal files
    std::string deps = o.output + ":";
    auto add = [&](const std::string& f) {
      std::string e;
      for (char c : std::filesystem::absolute(f).string()) e += (c == ' ' ? std::string("\\ ") : std::string(1, c));
      deps += " " + e;
    };
    for (const std::string& f : model_files(model)) add(f);
    write_file_atomically(o.depfile, deps + "\n");
  }
  const auto* udot = emitted.find("udot");
  const std::string code = udot->kernels.empty() ? "straight-line code"
                                                 : fmt::format("compact code: {} kernels, {} calls", udot->kernels.size(),
                                                               udot->kernel_calls);
  fmt::print(stderr, "{}: u_dot {} operations ({} form, {}), M {}, F {}\n", o.output, udot->ops.total(),
             emitted.udot_form, code, emitted.find("mass_matrix")->ops.total(), emitted.find("forcing")->ops.total());
  return 0;
}

}  // namespace generate_command

Subcommand add_generate(CLI::App& app) {
  auto o = std::make_shared<generate_command::Options>();
  CLI::App* c = app.add_subcommand("generate", "write the specialized C++ header of a model");
  add_model_option(c, o->model);
  c->add_option("-o,--output", o->output, "output header (.hpp)")->required();
  c->add_option("--entry", o->entry, "also write the C entry file (table of the functions; #includes the header)");
  c->add_option("--manifest", o->manifest, "also write the JSON manifest (functions, operation counts, hashes)");
  c->add_option("--depfile", o->depfile, "also write a Make-style dependency file (model and modal files)");
  c->add_option("--udot-form", o->form, "auto (fewer operations) | composite (M, F, tree LTDL) | articulated (O(n))")
      ->check(CLI::IsMember({"auto", "composite", "articulated"}))
      ->capture_default_str();
  c->add_option("--udot-code", o->code,
                "auto (by size) | straight-line (one function) | compact (kernels shared by bodies of one shape)")
      ->check(CLI::IsMember({"auto", "straight-line", "compact"}))
      ->capture_default_str();
  return {c, [o] { return generate_command::run(*o); }};
}

}  // namespace kanegen::cli
