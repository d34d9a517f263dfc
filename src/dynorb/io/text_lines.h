// Line-oriented text parsing shared by the TUM readers: comments ('#'), blank lines, fields
// separated by spaces/tabs/commas, strict number parsing with file:line error messages.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace dynorb {

// Calls `fn(line_number, fields)` for each non-comment, non-blank line. Throws InputError if the
// file cannot be opened. Reads the file as a stream (does not load it all at once).
void ForEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn);

std::vector<std::string> SplitFields(const std::string& line);

// Parses a finite double; throws InputError "file:line: ..." otherwise.
double ParseDouble(const std::string& text, const std::string& file, int line);

}  // namespace dynorb
