// Line-oriented text parsing shared by the TUM readers: comments ('#'), blank lines, fields
// separated by spaces/tabs/commas, strict number parsing with file:line error messages.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace dynorb {

// Calls `fn(line_number, fields)` for each non-comment, non-blank line. Reads the file as a
// stream (does not load it all at once), so a pipe (`--est <(cat f)`) or a character device
// reads like a regular file. Throws InputError "file not found: P" when there is no P,
// "P is a directory, not a file", or "cannot open P".
void ForEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn);

std::vector<std::string> SplitFields(const std::string& line);

// Parses a finite double in decimal notation ("-1.5", "2e-3", ".5"; an underflow such as
// "1e-320" gives the tiny or zero value); throws InputError "file:line: ..." otherwise: "not a
// number" (hex such as "0x10", a NUL or other stray byte), "non-finite value" ("nan", "inf"),
// "number out of range" ("1e999").
double ParseDouble(const std::string& text, const std::string& file, int line);

}  // namespace dynorb
