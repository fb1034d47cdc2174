// A straight-line program under construction: every non-trivial
// intermediate quantity of the symbolic formulation is bound to a temporary
// symbol by let(), with common-subexpression elimination (structurally equal
// expressions share one temporary). This keeps every expression small, so
// the emitted code grows with the number of operations the recursive
// formulation performs, not with the size of expanded closed forms.
//
// Temporaries are named tNNN unless let() is given a name (e.g. "ant2_w_B_x":
// what the quantity is, with its frame), and section() inserts comment
// markers ("// ---- body ant2: outward pass (velocities)") that appear in the
// emitted code above the first live temporary that follows them.
#pragma once

#include <ginac/ginac.h>

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "codegen/printer.hpp"

namespace kanegen::codegen {

using GiNaC::ex;

/// A function body split into parts of bounded size (Program::emit_chunked):
/// parts[i] are the bodies of helper functions called in order, which leave
/// the temporaries later parts need in a workspace `w`; `main` reads them
/// from there and holds the statements.
struct ChunkedBody {
  std::vector<std::string> parts;
  std::string main;
  int workspace = 0;  ///< number of workspace entries
};

/// The names of the symbols in e (temporaries, state, constants).
void collect_symbols(const ex& e, std::set<std::string>& names);

class Program {
 public:
  /// Applied to every expression before it is bound or assigned (e.g. the
  /// folding of constant subexpressions into derived constants, constants.hpp).
  std::function<ex(const ex&)> fold;

  /// Binds e to a temporary (reusing one for an equal expression); numbers,
  /// symbols and a number times a symbol are returned as they are. A new
  /// temporary takes `name` when given (made unique with a suffix).
  ex let(const ex& e, const std::string& name = {});
  /// Records `lhs = e;` as an output statement (in order).
  void assign(const std::string& lhs, const ex& e);
  /// A plain statement emitted verbatim after the temporaries it needs
  /// (e.g. `if (D3 <= 0) return 4;`), depending on expression `dep`.
  void statement(const std::string& text, const ex& dep);
  /// A comment marker for the temporaries bound after it.
  void section(const std::string& title);
  /// A statement emitted before every temporary, verbatim, that defines the
  /// symbols `defines` (e.g. the prescribed motion of a joint at t); emitted
  /// only when one of them is needed.
  void prelude(const std::string& text, const std::vector<std::string>& defines);
  /// sin and cos of `angle`, a function of the state, the time, the runtime parameters and the preludes'
  /// values only (no temporary): the symbols angle_s[i] and angle_c[i], computed with every other angle's
  /// in one batch after the preludes (kanegen_sincos_n, templates/joint_sincos.inc); the same angle
  /// gives the same symbols.
  std::pair<ex, ex> sincos(const ex& angle);
  /// Whether `e` reads a temporary of this program (else only the state, time, parameters, constants and
  /// preludes' values: what sincos() takes).
  bool reads_temporary(const ex& e) const;
  /// Whether some angle's sin and cos were asked for (the header then needs templates/joint_sincos.inc).
  bool has_sincos() const { return !angles_.empty(); }

  /// C++ body: temporaries that some output needs (dead ones dropped), in
  /// order, as `const T name = ...;`, then the outputs. Counts operations.
  std::string emit(const std::string& indent, OpCount& ops) const;
  /// The same code in parts of at most about `max_chunk_ops` operations: the
  /// compiler's time and memory on one straight-line function grow faster
  /// than linearly with its length, on a sequence of short ones linearly.
  ChunkedBody emit_chunked(const std::string& indent, OpCount& ops, long max_chunk_ops) const;
  /// Names of the temporaries bound so far.
  const std::set<std::string>& names() const { return names_; }

  /// What emit() prints, as data (for other emissions, outlined_code.hpp): the live temporaries in order,
  /// each with the section marker printed above it (empty: none), then the statements.
  struct LiveTemp {
    GiNaC::symbol sym;
    ex value;
    std::string section;  ///< the marker that precedes it, or empty
  };
  struct Statement {
    std::string lhs;   ///< empty: a verbatim statement `text` that depends on `value`
    std::string text;
    ex value;
  };
  struct Listing {
    std::vector<LiveTemp> temps;
    std::vector<Statement> statements;
    std::string preludes;  ///< the preludes some live expression needs, indented, one per line, then the angles'
                           ///< batch (into local arrays)
    OpCount prelude_ops;   ///< their operations (the angles' sums, and a sin and a cos per angle)
    int angles = 0;        ///< the batch's angles (0: none needed)
    std::string plain_preludes;  ///< the preludes without the batch
    std::string angle_list;      ///< the batch's arguments, printed, comma-separated
  };
  Listing listing(const std::string& indent) const;
  /// The operations of the live code by pass: the sections' titles without their body ("body link3: outward
  /// pass (velocities)" counts as "outward pass (velocities)"), in order of first appearance; the outputs'
  /// own operations as "outputs".
  std::vector<std::pair<std::string, long>> ops_by_pass() const;

 private:
  /// Which temporaries some statement needs; `needed` gets their symbols.
  std::vector<bool> liveness(std::set<std::string>& needed) const;
  /// Fills `out`'s preludes: those that define a symbol in `needed`, one line each, then the angles' batch
  /// when one of its symbols is needed (its operations in out.prelude_ops).
  void used_preludes(const std::set<std::string>& needed, const std::string& indent, Listing& out) const;
  struct Temp {
    GiNaC::symbol sym;
    ex value;
    std::string section;  ///< non-empty: a comment marker, not a temporary
  };
  std::vector<Temp> temps_;
  std::map<ex, ex, GiNaC::ex_is_less> cse_;
  std::set<std::string> names_;
  int unnamed_ = 0;
  struct Stmt {
    std::string lhs;  // empty for verbatim statements
    std::string text;
    ex value;
  };
  std::vector<Stmt> stmts_;
  struct Prelude {
    std::string text;
    std::vector<std::string> defines;
  };
  std::vector<Prelude> preludes_;
  struct Angle {
    ex angle;
    GiNaC::symbol s, c;
  };
  std::vector<Angle> angles_;
  std::map<ex, std::size_t, GiNaC::ex_is_less> angle_index_;
};

}  // namespace kanegen::codegen
