// NASTRAN bulk data read as cards (issue 36): the three field formats (free
// field with commas, small field of 8 columns, large field of 16 columns with
// a '*' after the name), continuation lines ('+' or '*' in column 1, a blank
// first field, or a free-field line starting with ','), comments ('$'),
// INCLUDE files (relative to the including file) and the bulk section of a
// full input file (after BEGIN BULK, up to ENDDATA). Each card keeps its file
// and line, so every fault found later names them.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace kanegen::nastran {

/// One logical card: its name and its data fields. Data field i (0-based) is the card's field 2 + i % 8 on
/// its (logical) line 1 + i / 8: fields 2..9 of the first line, then fields 2..9 of each continuation (a
/// large-field card's two physical lines make one logical line of 8 fields).
struct Card {
  std::string name;                 ///< upper case, without the large-field '*'
  std::vector<std::string> fields;  ///< trimmed text; "" for a blank field
  std::string file;                 ///< the file it was read from, as named (the input or an INCLUDE)
  int line = 0;                     ///< its first line in that file

  bool blank(int i) const { return i >= static_cast<int>(fields.size()) || fields[i].empty(); }
  /// The field as an integer; `fallback` when blank (else a blank field is refused). Throws InputError naming
  /// file, line, card and field.
  int integer(int i, std::optional<int> fallback = std::nullopt) const;
  /// The field as a real (NASTRAN forms: 1.5, 1.5E-3, 1.5D-3, 1.5-3, .5, 2.; an integer is taken as its value);
  /// `fallback` when blank.
  double real(int i, std::optional<double> fallback = std::nullopt) const;
  /// The field's text, upper case.
  std::string text(int i) const;
  /// "CONM2 21 (field 5 of line 1)": how diagnostics name a field.
  std::string where(int i) const;
  /// Throws InputError at this card's file and line, naming the card and `field` (if >= 0).
  [[noreturn]] void refuse(int field, const std::string& message) const;
};

/// A number in NASTRAN's real-field forms, or nullopt if the text is none.
std::optional<double> parse_real(const std::string& text);

/// An integer within int's range written in full ("12", "-3"), or nullopt.
std::optional<int> parse_integer(const std::string& text);

/// The whitespace-separated words of a line of printed output (an f06, a punch file).
std::vector<std::string> words(const std::string& line);

/// The bulk data cards of `path` and of the files it includes, in order. A file with a BEGIN BULK line is read
/// from after it; ENDDATA ends the reading. Throws InputError (file, line) for a file that cannot be read, an
/// INCLUDE that cannot be found or includes itself, a line that is no card, a continuation without a card.
std::vector<Card> read_cards(const std::string& path);

}  // namespace kanegen::nastran
