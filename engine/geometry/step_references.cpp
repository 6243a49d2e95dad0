// The entity references of a STEP file's DATA section, read from its text: a file that refers
// to an entity it does not define, or whose references form a cycle, is refused before
// OpenCASCADE sees it (OpenCASCADE 7.6 follows an ORIENTED_EDGE's edge recursively until the
// stack overflows when the edge is missing or is the oriented edge itself; found by fuzz_step).
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "geometry/detail/step_common.h"

namespace wrap::detail {

namespace {

// Reads "#123" at text[i] (i at '#'): the number, or -1; `i` moves past it.
long ReadEntityId(const std::string& text, size_t& i) {
  size_t j = i + 1;
  long id = 0;
  while (j < text.size() && text[j] >= '0' && text[j] <= '9' && j - i < 18) {
    id = id * 10 + (text[j] - '0');
    ++j;
  }
  const bool ok = j > i + 1;
  i = j;
  return ok ? id : -1;
}

// Each entity of the text ("#N = ...;", strings and comments skipped) with the entities it names.
std::map<long, std::vector<long>> References(const std::string& text) {
  std::map<long, std::vector<long>> refs;
  long current = -1;  // the entity whose record is being read
  bool in_data = false;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\'') {  // a string: '' is an escaped quote
      for (++i; i < text.size(); ++i) {
        if (text[i] == '\'' && !(i + 1 < text.size() && text[i + 1] == '\'')) break;
        if (text[i] == '\'') ++i;
      }
      ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      const size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 2;
    } else if (!in_data) {
      in_data = text.compare(i, 5, "DATA;") == 0;
      ++i;
    } else if (c == '#') {
      const long id = ReadEntityId(text, i);
      if (id < 0) continue;
      if (current < 0) {
        current = id;
        refs[current];
      } else {
        refs[current].push_back(id);
      }
    } else if (c == ';') {
      current = -1;
      ++i;
    } else {
      if (current < 0 && text.compare(i, 7, "ENDSEC;") == 0) in_data = false;
      ++i;
    }
  }
  return refs;
}

}  // namespace

std::string FindBrokenReference(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::map<long, std::vector<long>> refs = References(text);
  for (const auto& [id, named] : refs) {
    for (long r : named) {
      if (!refs.count(r)) {
        return "entity #" + std::to_string(id) + " refers to #" + std::to_string(r) +
               ", which the file does not define";
      }
    }
  }
  // Depth-first, without recursion (a long chain of references must not overflow our stack
  // either): 0 unvisited, 1 on the current path, 2 done.
  std::map<long, int> state;
  for (const auto& [root, unused] : refs) {
    if (state[root] != 0) continue;
    std::vector<std::pair<long, size_t>> stack{{root, 0}};
    state[root] = 1;
    while (!stack.empty()) {
      auto& [node, next] = stack.back();
      const auto it = refs.find(node);
      if (it == refs.end() || next >= it->second.size()) {
        state[node] = 2;
        stack.pop_back();
        continue;
      }
      const long child = it->second[next++];
      const int s = state[child];
      if (s == 1) {
        std::string cycle = "#" + std::to_string(child);
        bool on = false;
        for (const auto& [n, unused2] : stack) {
          if (n == child) on = true;
          if (on && n != child) cycle += " -> #" + std::to_string(n);
        }
        return "its entities refer to each other in a cycle (" + cycle + " -> #" +
               std::to_string(child) + ")";
      }
      if (s == 0) {
        state[child] = 1;
        stack.emplace_back(child, 0);
      }
    }
  }
  return {};
}

}  // namespace wrap::detail
