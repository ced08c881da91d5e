// SPDX-License-Identifier: GPL-3.0-or-later
// JSON documents (run summaries, reports, caches) through nlohmann-json. Object keys keep
// insertion order so that summaries diff cleanly between runs; non-finite numbers are written
// as null, since JSON has no representation for them.
#pragma once
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace arlequin {

using Json = nlohmann::ordered_json;

// The document, indented by two spaces, through a temporary file and a rename. A string that is
// not valid UTF-8 (a name or a path from the user's file system) is written with U+FFFD for
// each bad byte, so the file is always JSON.
inline void write_json_atomically(const std::filesystem::path& path, const Json& json) {
  write_file_atomically(path, json.dump(2, ' ', false, Json::error_handler_t::replace) + '\n');
}

// The whole file as one document; InputError naming the file when it cannot be read or is not
// JSON (with the parser's byte offset).
inline Json read_json_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw InputError(path.string() + ": not a JSON document (" + e.what() + ")");
  }
}

}  // namespace arlequin
