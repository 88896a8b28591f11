// The xacro expander: walks the source documents in order and builds the output document, as
// xacro does: properties and macros in scopes (a macro call opens one whose parent is the
// caller's, the dynamic scoping of xacro), blocks evaluated in the caller's scope.
#include <shapectl/robot/xacro_expander.hpp>

#include <tinyxml.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <optional>
#include <set>

#include <shapectl/io/input_error.hpp>
#include <shapectl/io/input_file.hpp>
#include <shapectl/robot/mesh_resource.hpp>
#include <shapectl/robot/xacro_expression.hpp>
#include <shapectl/robot/xml_depth.hpp>

namespace shapectl {

namespace fs = std::filesystem;

namespace {

struct Scope;

// A block: a macro's *param (the element) or **param (its children), or a block property.
struct Block {
  const TiXmlElement* element = nullptr;
  std::shared_ptr<Scope> scope;  // where it is evaluated: the caller's scope
  bool content_only = false;
};

struct Param {
  std::string name;
  int block_stars = 0;  // 1: *name, 2: **name
  std::optional<std::string> default_text;
  bool forward = false;  // name:=^ or name:=^|default: the caller's property of that name
};

struct Macro {
  const TiXmlElement* body = nullptr;
  std::vector<Param> params;
};

struct Scope {
  std::shared_ptr<Scope> parent;
  std::map<std::string, XacroValue> properties;
  std::map<std::string, Block> blocks;
  std::map<std::string, Macro> macros;

  template <class T>
  static const T* find(const Scope* scope, std::map<std::string, T> Scope::*table,
                       const std::string& name) {
    for (; scope; scope = scope->parent.get())
      if (auto it = (scope->*table).find(name); it != (scope->*table).end()) return &it->second;
    return nullptr;
  }
};

// The tags of the supported subset, and those of xacro this expander does not implement.
const std::set<std::string> supported_tags = {"property", "macro", "include",     "if",
                                              "unless",   "arg",   "insert_block"};
const std::set<std::string> unsupported_tags = {"call", "element", "attribute", "eval-comments",
                                                "load_yaml"};
// xacro's old syntax, tags without the prefix: copied as they are they would silently do nothing.
const std::set<std::string> legacy_tags = {"include", "property", "macro"};

bool is_top_level(const TiXmlElement* element) {
  const TiXmlNode* parent = element->Parent();
  return parent && parent->ToElement() && parent->Parent() && parent->Parent()->ToDocument();
}

// Splits a macro's params at blanks outside single quotes: xyz:='0 0 0' is one parameter.
std::vector<std::string> split_params(const std::string& text) {
  std::vector<std::string> out;
  std::string current;
  bool quoted = false;
  for (char c : text) {
    if (c == '\'') quoted = !quoted;
    if (!quoted && std::isspace(static_cast<unsigned char>(c))) {
      if (!current.empty()) out.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) out.push_back(current);
  return out;
}

class Expander {
 public:
  explicit Expander(const XacroOptions& options) : options_(options), args_(options.args) {}

  std::string run(const fs::path& file) {
    const TiXmlElement* root = load(file);
    include_stack_.push_back(canonical(file));
    auto global = std::make_shared<Scope>();
    TiXmlDocument out;
    out.LinkEndChild(new TiXmlDeclaration("1.0", "", ""));
    auto* out_root = new TiXmlElement(root->Value());
    out.LinkEndChild(out_root);
    copy_attributes(root, *global, out_root);
    process_children(root, global, out_root);
    TiXmlPrinter printer;
    printer.SetIndent("  ");
    out.Accept(&printer);
    std::string text = printer.Str();
    if (text.size() > max_urdf_file_bytes)
      throw InputError(file.string(), "",
                       "expands to more than the " + std::to_string(max_urdf_file_bytes) +
                           " byte limit for URDF files");
    return text;
  }

 private:
  // Parses `file` and keeps the document: macros and blocks point into it.
  const TiXmlElement* load(const fs::path& file) {
    const std::string text = read_input_file(file, max_urdf_file_bytes, "xacro");
    if (const std::size_t at = xml_too_deep_at(text, max_xml_depth); at != std::string::npos)
      throw InputError(file.string() + ":" + std::to_string(line_at(text, at)), "",
                       "elements nested deeper than " + std::to_string(max_xml_depth));
    auto doc = std::make_unique<TiXmlDocument>();
    doc->Parse(text.c_str(), nullptr, TIXML_ENCODING_UTF8);
    if (doc->Error())
      throw InputError(file.string() + ":" + std::to_string(doc->ErrorRow()), "",
                       std::string("not well-formed XML (") + doc->ErrorDesc() + ")");
    const TiXmlElement* root = doc->RootElement();
    if (!root) throw InputError(file.string(), "", "no root element (expected <robot>)");
    files_[doc.get()] = file;
    documents_.push_back(std::move(doc));
    return root;
  }

  // The file's identity for the include-cycle check; the path as given when it cannot be resolved.
  static fs::path canonical(const fs::path& file) {
    std::error_code error;
    fs::path resolved = fs::weakly_canonical(file, error);
    return error ? file : resolved;
  }

  static int line_at(const std::string& text, std::size_t at) {
    return 1 +
           static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
  }

  fs::path file_of(const TiXmlNode* node) const {
    const auto it = files_.find(node->GetDocument());
    return it == files_.end() ? fs::path() : it->second;
  }

  [[noreturn]] void fail(const TiXmlNode* node, const std::string& problem) const {
    throw InputError(file_of(node).string() + ":" + std::to_string(node->Row()), "", problem);
  }

  void count_output(const TiXmlNode* node, std::size_t bytes) {
    produced_bytes_ += bytes;
    if (produced_bytes_ > max_urdf_file_bytes)
      fail(node, "the expansion grows past the " + std::to_string(max_urdf_file_bytes) +
                     " byte limit for URDF files (a macro expanding too often?)");
  }

  // ---- text: ${expression}, $(substitution), $${ and $$( escapes ----

  XacroValue eval_text(const std::string& text, const Scope& scope, const TiXmlNode* node) {
    std::vector<XacroValue> parts;
    std::string literal;
    bool has_literal = false;
    auto flush = [&] {
      if (!literal.empty()) {
        parts.push_back(XacroValue::string(literal));
        has_literal = true;
      }
      literal.clear();
    };
    for (std::size_t i = 0; i < text.size();) {
      if (text.compare(i, 3, "$${") == 0 || text.compare(i, 3, "$$(") == 0) {
        literal += text.substr(i + 1, 2);
        i += 3;
      } else if (text.compare(i, 2, "${") == 0) {
        const std::size_t end = closing(text, i + 2, '{', '}');
        if (end == std::string::npos)
          fail(node, "'${' without its closing '}' in \"" + bounded_preview(text) + "\"");
        flush();
        const std::string expression = text.substr(i + 2, end - i - 2);
        const Scope* lookup_scope = &scope;
        const XacroLookup lookup =
            [lookup_scope](const std::string& name) -> std::optional<XacroValue> {
          if (const XacroValue* v = Scope::find(lookup_scope, &Scope::properties, name)) return *v;
          return std::nullopt;
        };
        try {
          parts.push_back(evaluate_xacro_expression(expression, lookup));
        } catch (const XacroExpressionError& e) {
          fail(node, "bad expression ${" + bounded_preview(expression) + "}: " + e.what());
        }
        i = end + 1;
      } else if (text.compare(i, 2, "$(") == 0) {
        const std::size_t end = closing(text, i + 2, '(', ')');
        if (end == std::string::npos)
          fail(node, "'$(' without its closing ')' in \"" + bounded_preview(text) + "\"");
        flush();
        parts.push_back(XacroValue::string(substitution(text.substr(i + 2, end - i - 2), node)));
        i = end + 1;
      } else {
        literal += text[i++];
      }
    }
    flush();
    if (parts.size() == 1 && !has_literal) return parts.front();  // typed, as xacro returns it
    std::string joined;
    for (const auto& p : parts) joined += xacro_text(p);
    return XacroValue::string(joined);
  }

  std::string text_of(const std::string& text, const Scope& scope, const TiXmlNode* node) {
    return xacro_text(eval_text(text, scope, node));
  }

  // Where the bracket opened before `from` closes, skipping quoted text; npos if it does not.
  static std::size_t closing(const std::string& text, std::size_t from, char open, char close) {
    int depth = 1;
    char quote = 0;
    for (std::size_t i = from; i < text.size(); ++i) {
      const char c = text[i];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '\'' || c == '"') {
        quote = c;
      } else if (c == open) {
        ++depth;
      } else if (c == close && --depth == 0) {
        return i;
      }
    }
    return std::string::npos;
  }

  std::string substitution(const std::string& inner, const TiXmlNode* node) {
    std::vector<std::string> words = split_params(inner);
    if (words.empty()) fail(node, "empty $() substitution");
    const std::string& command = words[0];
    auto need = [&](std::size_t lo, std::size_t hi) {
      if (words.size() < lo || words.size() > hi)
        fail(node, "$(" + inner + "): expected $(" + command +
                       (command == "optenv" ? " NAME [DEFAULT])" : " NAME)"));
    };
    if (command == "find") {
      need(2, 2);
      return find_package(words[1], node).string();
    }
    if (command == "arg") {
      need(2, 2);
      const auto it = args_.find(words[1]);
      if (it == args_.end())
        fail(node, "undefined arg '" + words[1] + "' (declare it with <xacro:arg name=\"" +
                       words[1] + "\" default=\"...\"/> or give --xacro-arg " + words[1] +
                       ":=VALUE)");
      return it->second;
    }
    if (command == "env" || command == "optenv") {
      need(2, command == "env" ? 2 : 3);
      if (const char* value = std::getenv(words[1].c_str())) return value;
      if (command == "env")
        fail(node, "environment variable '" + words[1] + "' is not set for $(env)");
      return words.size() == 3 ? words[2] : "";
    }
    if (command == "dirname") {
      need(1, 1);
      return fs::absolute(file_of(node)).parent_path().string();
    }
    fail(node, "unsupported substitution $(" + command +
                   " ...) (supported: find, arg, env, optenv, dirname)");
  }

  // $(find pkg): the given package paths, $ROS_PACKAGE_PATH, then the folders above the file.
  fs::path find_package(const std::string& package, const TiXmlNode* node) {
    std::vector<fs::path> search = with_ros_package_path(options_.package_paths);
    for (fs::path dir = fs::absolute(file_of(node)).parent_path(); !dir.empty();
         dir = dir.parent_path()) {
      search.push_back(dir);
      if (dir == dir.parent_path()) break;
    }
    if (auto found = find_ros_package(package, search)) return *found;
    fail(node, "package '" + package + "' of $(find " + package +
                   ") not found (give --package-path DIR, the folder "
                   "holding it, or set ROS_PACKAGE_PATH)");
  }

  // ---- elements ----

  void copy_attributes(const TiXmlElement* source, const Scope& scope, TiXmlElement* out) {
    for (const TiXmlAttribute* a = source->FirstAttribute(); a; a = a->Next()) {
      const std::string name = a->Name();
      if (name == "xmlns:xacro") continue;
      const std::string value = text_of(a->ValueStr(), scope, source);
      count_output(source, name.size() + value.size() + 4);
      out->SetAttribute(name, value);
    }
  }

  void process_children(const TiXmlNode* source, const std::shared_ptr<Scope>& scope,
                        TiXmlNode* out) {
    for (const TiXmlNode* child = source->FirstChild(); child; child = child->NextSibling())
      process_node(child, scope, out);
  }

  void process_node(const TiXmlNode* node, const std::shared_ptr<Scope>& scope, TiXmlNode* out) {
    if (const TiXmlText* text = node->ToText()) {
      auto* copy = new TiXmlText(text_of(text->ValueStr(), *scope, node));
      copy->SetCDATA(text->CDATA());
      count_output(node, copy->ValueStr().size());
      out->LinkEndChild(copy);
      return;
    }
    if (node->ToComment()) {
      count_output(node, node->ValueStr().size() + 7);
      out->LinkEndChild(node->Clone());
      return;
    }
    const TiXmlElement* element = node->ToElement();
    if (!element) return;  // declarations and unknown nodes are not copied
    const std::string tag = element->ValueStr();
    if (tag.rfind("xacro:", 0) == 0) {
      xacro_element(element, tag.substr(6), scope, out);
      return;
    }
    if (legacy_tags.count(tag) && is_top_level(element))
      fail(element, "<" + tag +
                        "> without the xacro: prefix (xacro's old syntax) is not "
                        "supported: write <xacro:" +
                        tag + ">");
    auto* copy = new TiXmlElement(tag);
    count_output(node, 2 * tag.size() + 5);
    out->LinkEndChild(copy);
    copy_attributes(element, *scope, copy);
    process_children(element, scope, copy);
  }

  std::string required_attribute(const TiXmlElement* e, const char* name) const {
    const char* value = e->Attribute(name);
    if (!value) fail(e, std::string("<") + e->Value() + "> needs a " + name + "=\"...\" attribute");
    return value;
  }

  void xacro_element(const TiXmlElement* e, const std::string& what,
                     const std::shared_ptr<Scope>& scope, TiXmlNode* out) {
    if (what == "property") return define_property(e, scope);
    if (what == "macro") return define_macro(e, *scope);
    if (what == "include") return include(e, scope, out);
    if (what == "arg") return define_arg(e, *scope);
    if (what == "insert_block") return insert_block(e, scope, out);
    if (what == "if" || what == "unless") {
      if (condition(e, *scope) == (what == "if")) process_children(e, scope, out);
      return;
    }
    if (unsupported_tags.count(what))
      fail(e, "xacro:" + what +
                  " is not supported by shapectl's xacro expander (docs/robot.md: expand it "
                  "with ROS's xacro, `xacro robot.urdf.xacro > robot.urdf`)");
    call_macro(e, what, scope, out);
  }

  void define_property(const TiXmlElement* e, const std::shared_ptr<Scope>& scope) {
    const std::string name = required_attribute(e, "name");
    Scope* target = scope.get();
    if (const char* where = e->Attribute("scope")) {
      const std::string s = where;
      if (s == "parent") {
        if (target->parent) target = target->parent.get();
      } else if (s == "global") {
        while (target->parent) target = target->parent.get();
      } else {
        fail(e, "property scope '" + s + "': expected parent or global");
      }
    }
    const char* value = e->Attribute("value");
    const char* fallback = e->Attribute("default");
    if (!value && !fallback) {  // a block property: its children, inserted by insert_block
      target->blocks[name] = Block{e, scope, true};
      return;
    }
    if (!value && Scope::find(target, &Scope::properties, name)) return;  // default= only
    target->properties[name] = typed(eval_text(value ? value : fallback, *scope, e));
  }

  // Property and parameter text is typed like a Python literal (see xacro_literal).
  static XacroValue typed(const XacroValue& v) {
    return v.kind == XacroValue::Kind::string ? xacro_literal(v.text) : v;
  }

  void define_macro(const TiXmlElement* e, Scope& scope) {
    const std::string name = required_attribute(e, "name");
    Macro macro{e, {}};
    std::set<std::string> seen;
    for (const std::string& spec :
         split_params(e->Attribute("params") ? e->Attribute("params") : "")) {
      Param p;
      std::string text = spec;
      while (!text.empty() && text[0] == '*' && p.block_stars < 2) {
        ++p.block_stars;
        text.erase(0, 1);
      }
      const std::size_t assign = text.find('=');
      if (assign != std::string::npos) {
        if (p.block_stars)
          fail(e, "block parameter '" + spec + "' of macro '" + name + "' cannot have a default");
        std::string value = text.substr(assign + 1);
        text = text.substr(0, assign > 0 && text[assign - 1] == ':' ? assign - 1 : assign);
        if (value.rfind('^', 0) == 0) {
          p.forward = true;
          value.erase(0, 1);
          if (value.rfind('|', 0) == 0) value.erase(0, 1), p.default_text = value;
        } else {
          p.default_text = value;
        }
      }
      p.name = text;
      if (p.name.empty()) fail(e, "empty parameter name in params of macro '" + name + "'");
      if (!seen.insert(p.name).second)
        fail(e, "parameter '" + p.name + "' twice in macro '" + name + "'");
      macro.params.push_back(p);
    }
    scope.macros[name] = macro;
  }

  void define_arg(const TiXmlElement* e, const Scope& scope) {
    const std::string name = required_attribute(e, "name");
    if (args_.count(name)) return;  // given on the command line, or declared before
    if (const char* fallback = e->Attribute("default")) args_[name] = text_of(fallback, scope, e);
  }

  bool condition(const TiXmlElement* e, const Scope& scope) {
    const std::string raw = required_attribute(e, "value");
    const XacroValue v = eval_text(raw, scope, e);
    if (v.kind != XacroValue::Kind::string) return xacro_truth(v);
    if (v.text == "true" || v.text == "True" || v.text == "1") return true;
    if (v.text == "false" || v.text == "False" || v.text == "0") return false;
    const XacroValue number = xacro_literal(v.text);
    if (number.kind == XacroValue::Kind::integer) return number.number != 0;
    fail(e, "xacro:" + std::string(e->Value() + 6) + " value \"" + bounded_preview(raw) +
                "\" is \"" + bounded_preview(v.text) + "\": expected true, false, 1 or 0");
  }

  void include(const TiXmlElement* e, const std::shared_ptr<Scope>& scope, TiXmlNode* out) {
    if (e->Attribute("ns")) fail(e, "xacro:include with ns= (a namespace) is not supported");
    fs::path file = text_of(required_attribute(e, "filename"), *scope, e);
    if (file.empty()) fail(e, "xacro:include with an empty filename");
    if (file.is_relative()) file = file_of(e).parent_path() / file;
    std::error_code error;
    if (!fs::is_regular_file(file, error))
      fail(e, "included file '" + file.string() + "' not found");
    const fs::path identity = canonical(file);
    for (const fs::path& open : include_stack_)
      if (open == identity) fail(e, "include cycle: '" + file.string() + "' includes itself");
    if (static_cast<int>(include_stack_.size()) > max_xacro_include_depth)
      fail(e, "includes nested deeper than " + std::to_string(max_xacro_include_depth));
    const TiXmlElement* root = load(file);
    include_stack_.push_back(identity);
    process_children(root, scope, out);
    include_stack_.pop_back();
  }

  void insert_block(const TiXmlElement* e, const std::shared_ptr<Scope>& scope, TiXmlNode* out) {
    const std::string name = required_attribute(e, "name");
    const Block* block = Scope::find(scope.get(), &Scope::blocks, name);
    if (!block)
      fail(e, "undefined block '" + name + "' for xacro:insert_block (a *" + name +
                  " macro parameter or a block property)");
    const Block b = *block;  // the scope's map may grow while the block is expanded
    enter(e);
    if (b.content_only) process_children(b.element, b.scope, out);
    else process_node(b.element, b.scope, out);
    --depth_;
  }

  void enter(const TiXmlElement* e) {
    if (++depth_ > max_xacro_macro_depth)
      fail(e, "macros nested deeper than " + std::to_string(max_xacro_macro_depth) +
                  " (a macro calling itself?)");
  }

  void call_macro(const TiXmlElement* e, const std::string& name,
                  const std::shared_ptr<Scope>& scope, TiXmlNode* out) {
    const Macro* found = Scope::find(scope.get(), &Scope::macros, name);
    if (!found) {
      fail(e, "undefined macro 'xacro:" + name +
                  "' (expected a xacro:macro of that name, defined "
                  "before this call, or one of xacro:" +
                  join(supported_tags) + ")");
    }
    const Macro macro = *found;
    enter(e);
    auto local = std::make_shared<Scope>();
    local->parent = scope;
    for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const auto p = std::find_if(macro.params.begin(), macro.params.end(), [&](const Param& q) {
        return q.name == a->Name() && q.block_stars == 0;
      });
      if (p == macro.params.end())
        fail(e, "macro '" + name + "' has no parameter '" + a->Name() + "'");
      local->properties[p->name] = typed(eval_text(a->ValueStr(), *scope, e));
    }
    const TiXmlElement* next_block = e->FirstChildElement();
    for (const Param& p : macro.params) {
      if (p.block_stars) {
        if (!next_block)
          fail(e,
               "macro '" + name + "' expects a block (an element inside the call) for *" + p.name);
        local->blocks[p.name] = Block{next_block, scope, p.block_stars == 2};
        next_block = next_block->NextSiblingElement();
        continue;
      }
      if (local->properties.count(p.name)) continue;
      if (p.forward) {
        if (const XacroValue* v = Scope::find(scope.get(), &Scope::properties, p.name)) {
          local->properties[p.name] = *v;
          continue;
        }
        if (!p.default_text)
          fail(e, "macro '" + name + "' forwards parameter '" + p.name +
                      "' (:=^) but no property of that name is defined here");
      }
      if (!p.default_text)
        fail(e, "macro '" + name + "' needs parameter '" + p.name + "' (it has no default)");
      local->properties[p.name] = typed(eval_text(*p.default_text, *scope, e));
    }
    process_children(macro.body, local, out);
    --depth_;
  }

  static std::string join(const std::set<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", xacro:") + n;
    return s;
  }

  const XacroOptions& options_;
  std::map<std::string, std::string> args_;
  std::vector<std::unique_ptr<TiXmlDocument>> documents_;
  std::map<const TiXmlDocument*, fs::path> files_;
  std::vector<fs::path> include_stack_;
  int depth_ = 0;
  std::size_t produced_bytes_ = 0;
};

}  // namespace

std::string expand_xacro_file(const fs::path& file, const XacroOptions& options) {
  return Expander(options).run(file);
}

bool is_xacro_file(const fs::path& file) { return file.extension() == ".xacro"; }

}  // namespace shapectl
