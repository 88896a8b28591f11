#pragma once
// Where the page (web/) and the bundled scenes (scenes/) are when not given on the command line:
// installed beside the executable (P/bin → P/share/shapectl/web), beside its build directory
// (build/shapectl → web/), else in the source tree this was built from.
#include <filesystem>

namespace shapectl::server {

// The first of <exe dir>/../share/shapectl/web (installed), <exe dir>/../web,
// <exe dir>/../../web, <source>/web holding index.html;
// <source>/web when none does (the server then answers 404 and says so in the log).
std::filesystem::path default_web_root();
// The scenes/ directory beside default_web_root().
std::filesystem::path default_scenes_dir();

}  // namespace shapectl::server
