#include "apps/kanegen/cli_common.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <chrono>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/handover_engine.hpp"
#include "engine/jit.hpp"
#include "engine/jit_cache.hpp"
#include "engine/model_checks.hpp"
#include "model/diagnostics.hpp"
#include "engine/load_model.hpp"

namespace kanegen::cli {

namespace {
const auto kProcessStart = std::chrono::steady_clock::now();  // static initialization: before main
}  // namespace

void run_background_compile(const std::string& model_path, bool native, const std::string& log_path,
                            const std::function<void()>& started) {
  std::error_code ec;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  // spawned through /proc/self/exe (this very binary, even if it was replaced
  // on disk since), named as itself for ps
  std::vector<std::string> argv = {ec ? std::string("kanegen") : self, "compile", model_path, "--background"};
  if (native) argv.push_back("--native");
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  std::filesystem::create_directories(std::filesystem::path(log_path).parent_path(), ec);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, "/proc/self/exe", &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error(fmt::format("cannot start kanegen compile: {}", std::strerror(rc)));
  if (started) started();
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno == ECHILD) return;  // reaped elsewhere (SIGCHLD ignored): the cache says whether it built
    if (errno != EINTR) throw std::runtime_error(fmt::format("waiting for kanegen compile: {}", std::strerror(errno)));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  throw std::runtime_error(fmt::format("kanegen compile {} {} (its messages: {})", model_path,
                                       WIFEXITED(status) ? fmt::format("exited with status {}", WEXITSTATUS(status))
                                                         : fmt::format("was killed by signal {}", WTERMSIG(status)),
                                       log_path));
}

double seconds_since_start() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - kProcessStart).count();
}

Model load_checked(const std::string& path) {
  Model model = load_model(path);
  check_mass_matrix_at_initial_state(model);
  return model;
}

std::unique_ptr<Engine> make_engine(const Model& model, const std::string& name, bool native, bool derivatives,
                                    bool quick) {
  if (name == "generic") return std::make_unique<GenericEngine>(model);
  JitOptions jit;
  jit.native = native;
  jit.derivatives = derivatives;
  jit.quick = quick;
  if (name == "auto" && !derivatives && !jit_cached(model, codegen::jit_code_generator(), jit)) {
    const double t0 = seconds_since_start();
    fmt::print(stderr,
               "kanegen: no compiled code of {} cached: integrating on the generic engine from {:.2f} s on; "
               "its generated code is built in the background and takes over when ready\n",
               model.name, t0);
    const std::string log = (std::filesystem::path(resolved(jit).cache_dir) /
                             (jit_cache::file_stem(model.name) + "-background-build.log"))
                                .string();
    return std::make_unique<HandoverEngine>(
        model,
        [path = model.source_path, native, log](const std::function<void()>& started) {
          run_background_compile(path, native, log, started);
        },
        [&model, jit, t0]() -> std::unique_ptr<Engine> {
          JitOptions load = jit;
          load.quiet = true;
          if (!jit_cached(model, codegen::jit_code_generator(), load))
            throw std::runtime_error("the background build left no library in the cache");
          auto e = jit_load(model, codegen::jit_code_generator(), load);
          std::fprintf(stderr, "kanegen: generated code of %s built in the background in %.1f s: it takes over the run\n",
                       model.name.c_str(), seconds_since_start() - t0);
          return e;
        });
  }
  if (name == "generated" || name == "auto") {
    try {
      return jit_load(model, codegen::jit_code_generator(), jit);
    } catch (const JitError& e) {  // the generated code of this model does not compile
      throw InputError(Diagnostic{model.source_path, 0, "", e.what()});
    }
  }
  throw InputError(
      Diagnostic{"--engine", 0, "", fmt::format("unknown engine '{}'; expected generated, generic or auto", name)});
}

State state_for(const Model& model, const std::string& state_path) {
  return state_path.empty() ? initial_state(model) : load_state(model, state_path);
}

void add_model_option(CLI::App* c, std::string& model) {
  c->add_option("MODEL", model, "model file (YAML, model-format.md)")->required()->check(CLI::ExistingFile);
}

void add_engine_option(CLI::App* c, std::string& engine, bool& native, bool with_auto) {
  std::string help = "generated: the model's generated code (JIT-compiled, cached); generic: the numeric path";
  std::vector<std::string> names = {"generated", "generic"};
  if (with_auto) {
    help += "; auto: generated when cached (or an implicit method needs its Jacobian), else generic at once "
            "while the generated code is built, handing over when it is ready";
    names.push_back("auto");
  }
  c->add_option("--engine", engine, help)->check(CLI::IsMember(names))->capture_default_str();
  c->add_flag("--native", native,
              "compile the generated code for this machine's CPU (-march=native): faster, not portable");
}

}  // namespace kanegen::cli
