#pragma once

// The reader conformance table of spec/package.md Sec. 9.1, read from the
// spec's text so that tests follow the document: one row per rule, with what
// a reader does ("MUST refuse", "MUST ignore", ...) and what tests it (an
// invalid vector's name in backquotes, or unit tests naming their files).

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace casual3d::testing {

struct ConformanceRow {
  std::string rule;    // First cell, as written.
  std::string reader;  // "MUST refuse", "MUST ignore", "MAY accept / MAY refuse", ...
  std::string tested;  // Third cell, as written.
  // The invalid vector, when the third cell is exactly one backquoted name.
  std::string vector;
  // Files between backquotes in the third cell other than the vector
  // ("format/manifest_test.cc"), and vector names mentioned beside them.
  std::vector<std::string> quoted;
};

// Splits "| a | b | c |" into its trimmed cells.
inline std::vector<std::string> TableCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|') {
      const size_t b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
      cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return cells;
}

// The text between backquotes, in order.
inline std::vector<std::string> Backquoted(const std::string& text) {
  std::vector<std::string> out;
  for (size_t b = text.find('`'); b != std::string::npos; b = text.find('`', b)) {
    const size_t e = text.find('`', b + 1);
    if (e == std::string::npos) break;
    out.push_back(text.substr(b + 1, e - b - 1));
    b = e + 1;
  }
  return out;
}

// The rows of the first table after the heading `heading` in `markdown`
// (without its header and separator rows); empty if there is none.
inline std::vector<ConformanceRow> ParseConformanceTable(const std::string& markdown,
                                                         const std::string& heading) {
  std::vector<ConformanceRow> rows;
  std::istringstream in(markdown);
  std::string line;
  bool in_section = false, in_table = false;
  int table_line = 0;
  while (std::getline(in, line)) {
    if (!in_section) {
      in_section = line == heading;
      continue;
    }
    if (line.rfind("#", 0) == 0) break;  // The next heading.
    if (line.rfind("|", 0) != 0) {
      if (in_table) break;
      continue;
    }
    in_table = true;
    if (table_line++ < 2) continue;  // Header and separator.
    const std::vector<std::string> cells = TableCells(line);
    if (cells.size() != 3) continue;
    ConformanceRow row{cells[0], cells[1], cells[2], "", Backquoted(cells[2])};
    if (row.quoted.size() == 1 && row.tested == "`" + row.quoted[0] + "`") {
      row.vector = row.quoted[0];
      row.quoted.clear();
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

inline std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace casual3d::testing
