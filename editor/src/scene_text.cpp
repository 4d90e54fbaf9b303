#include "scene_text.h"

#include <libfyaml.h>

#include <QStringList>

#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

namespace studio {

namespace {

/* A YAML node with its byte span in the text it was parsed from. */
struct YNode {
  enum Type { Scalar, Map, Seq } type = Scalar;
  bool flow = false;         /* a flow collection ({...} or [...]) */
  bool block_scalar = false; /* | or > : not spliced */
  size_t start = 0, end = 0; /* [start, end) in the text; block collections end at their last child */
  int col = 0;               /* column of start */
  QByteArray text;           /* scalar content */
  std::vector<std::pair<std::unique_ptr<YNode>, std::unique_ptr<YNode>>> pairs;
  std::vector<std::unique_ptr<YNode>> items;

  const YNode *Get(const QByteArray &key) const {
    for (const auto &p : pairs)
      if (p.first->type == Scalar && p.first->text == key) return p.second.get();
    return nullptr;
  }
};

struct Builder {
  std::vector<std::unique_ptr<YNode>> stack;
  std::vector<std::unique_ptr<YNode>> pending_key; /* per stack level (maps) */
  std::unique_ptr<YNode> root;
  bool ok = true;

  void Attach(std::unique_ptr<YNode> n) {
    if (stack.empty()) {
      root = std::move(n);
      return;
    }
    YNode *p = stack.back().get();
    if (p->type == YNode::Seq) {
      p->items.push_back(std::move(n));
    } else if (!pending_key.back()) {
      pending_key.back() = std::move(n);
    } else {
      p->pairs.emplace_back(std::move(pending_key.back()), std::move(n));
    }
  }
};

std::unique_ptr<YNode> Parse(const QByteArray &text) {
  struct fy_parse_cfg cfg;
  std::memset(&cfg, 0, sizeof cfg);
  cfg.flags = static_cast<enum fy_parse_cfg_flags>(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2);
  struct fy_parser *fyp = fy_parser_create(&cfg);
  if (!fyp) return nullptr;
  if (fy_parser_set_string(fyp, text.constData(), static_cast<size_t>(text.size())) != 0) {
    fy_parser_destroy(fyp);
    return nullptr;
  }
  Builder b;
  int docs = 0;
  struct fy_event *e = nullptr;
  while (b.ok && (e = fy_parser_parse(fyp)) != nullptr) {
    const struct fy_mark *sm = fy_event_start_mark(e), *em = fy_event_end_mark(e);
    switch (e->type) {
    case FYET_DOCUMENT_START:
      if (++docs > 1) b.ok = false;
      break;
    case FYET_MAPPING_START:
    case FYET_SEQUENCE_START: {
      auto n = std::make_unique<YNode>();
      n->type = e->type == FYET_MAPPING_START ? YNode::Map : YNode::Seq;
      if (!sm) {
        b.ok = false;
        break;
      }
      n->start = sm->input_pos;
      n->col = sm->column;
      n->flow = n->start < static_cast<size_t>(text.size()) && (text[int(n->start)] == '{' || text[int(n->start)] == '[');
      b.stack.push_back(std::move(n));
      b.pending_key.emplace_back();
      break;
    }
    case FYET_MAPPING_END:
    case FYET_SEQUENCE_END: {
      if (b.stack.empty()) {
        b.ok = false;
        break;
      }
      std::unique_ptr<YNode> n = std::move(b.stack.back());
      b.stack.pop_back();
      if (b.pending_key.back()) b.ok = false; /* a key without value */
      b.pending_key.pop_back();
      if (n->flow) {
        n->end = em ? em->input_pos : n->start;
      } else {
        n->end = n->start;
        if (!n->pairs.empty()) n->end = n->pairs.back().second->end;
        if (!n->items.empty()) n->end = n->items.back()->end;
      }
      b.Attach(std::move(n));
      break;
    }
    case FYET_SCALAR: {
      auto n = std::make_unique<YNode>();
      if (!sm || !em) {
        b.ok = false;
        break;
      }
      n->start = sm->input_pos;
      n->end = em->input_pos;
      n->col = sm->column;
      size_t len = 0;
      const char *t = fy_token_get_text(e->scalar.value, &len);
      n->text = QByteArray(t ? t : "", static_cast<int>(t ? len : 0));
      const enum fy_scalar_style st = fy_token_scalar_style(e->scalar.value);
      if (st == FYSS_SINGLE_QUOTED || st == FYSS_DOUBLE_QUOTED) {
        const char q = st == FYSS_SINGLE_QUOTED ? '\'' : '"';
        // The marks may or may not include the quotes: make the span include them.
        if (n->start > 0 && text[int(n->start)] != q && text[int(n->start - 1)] == q) {
          --n->start;
          --n->col;
        }
        if (n->end < static_cast<size_t>(text.size()) && (n->end == 0 || text[int(n->end - 1)] != q) &&
            text[int(n->end)] == q)
          ++n->end;
      } else if (st == FYSS_LITERAL || st == FYSS_FOLDED) {
        n->block_scalar = true;
      }
      b.Attach(std::move(n));
      break;
    }
    case FYET_ALIAS: b.ok = false; break; /* anchors and aliases are not spliced */
    default: break;
    }
    fy_parser_event_free(fyp, e);
  }
  const bool failed = fy_parser_get_stream_error(fyp);
  fy_parser_destroy(fyp);
  if (!b.ok || failed || !b.root || b.root->type != YNode::Map) return nullptr;
  return std::move(b.root);
}

QByteArray Span(const QByteArray &text, const YNode *n) {
  return text.mid(static_cast<int>(n->start), static_cast<int>(n->end - n->start));
}

/* One splice of the user's text. */
struct Splice {
  size_t start, end;
  QByteArray text;
  int order;
};

class Merger {
public:
  Merger(const QByteArray &user, const QByteArray &co, const QByteArray &cn) : user_(user), co_(co), cn_(cn) {}
  bool ok = true;
  std::vector<Splice> splices;
  QStringList replaced;

  bool Same(const YNode *o, const YNode *n) const { return Span(co_, o) == Span(cn_, n); }

  /* @p n (of the new canonical text) as flow text: valid at any value position. */
  QByteArray Flow(const YNode *n) const {
    if (n->type == YNode::Scalar || n->flow) {
      QByteArray t = Span(cn_, n);
      if (t.contains('\n')) t = t.simplified();
      return t;
    }
    QByteArray out = n->type == YNode::Map ? "{" : "[";
    bool first = true;
    if (n->type == YNode::Map) {
      for (const auto &p : n->pairs) {
        if (!first) out += ", ";
        first = false;
        out += Span(cn_, p.first.get()) + ": " + Flow(p.second.get());
      }
    } else {
      for (const auto &i : n->items) {
        if (!first) out += ", ";
        first = false;
        out += Flow(i.get());
      }
    }
    out += n->type == YNode::Map ? "}" : "]";
    return out;
  }

  /* A block node of the new canonical text re-indented to start at column @p col. */
  QByteArray Block(const YNode *n, int col) const {
    const QByteArray t = Span(cn_, n);
    const int delta = col - n->col;
    QList<QByteArray> lines = t.split('\n');
    for (int i = 1; i < lines.size(); ++i) {
      if (delta > 0) {
        lines[i] = QByteArray(delta, ' ') + lines[i];
      } else if (delta < 0) {
        int k = 0;
        while (k < -delta && k < lines[i].size() && lines[i][k] == ' ') ++k;
        lines[i] = lines[i].mid(k);
      }
    }
    return lines.join('\n');
  }

  void Replace(const YNode *u, const YNode *n, const QString &path) {
    if (u->block_scalar) {
      ok = false;
      return;
    }
    const bool block_here = (u->type != YNode::Scalar && !u->flow);
    const bool block_new = (n->type != YNode::Scalar && !n->flow);
    QByteArray t = block_here && block_new ? Block(n, u->col) : Flow(n);
    splices.push_back(Splice{u->start, u->end, t, order_++});
    if (u->type != YNode::Scalar || n->type != YNode::Scalar) replaced << path;
  }

  /* The pairs of the mapping @p n that differ from the mapping @p o (both canonical), as flow
     text or as block lines at column @p col: a section the user's file leaves to the defaults
     gets only the keys that changed. */
  QByteArray PartialFlow(const YNode *o, const YNode *n) const {
    QByteArray out = "{";
    for (const auto &np : n->pairs) {
      const YNode *ov = o->Get(np.first->text);
      if (ov && Same(ov, np.second.get())) continue;
      if (out.size() > 1) out += ", ";
      const bool maps = ov && ov->type == YNode::Map && np.second->type == YNode::Map;
      out += Span(cn_, np.first.get()) + ": " + (maps ? PartialFlow(ov, np.second.get()) : Flow(np.second.get()));
    }
    return out + "}";
  }
  QByteArray PartialBlock(const YNode *o, const YNode *n, int col) const {
    QList<QByteArray> lines;
    for (const auto &np : n->pairs) {
      const YNode *ov = o->Get(np.first->text);
      const YNode *nv = np.second.get();
      if (ov && Same(ov, nv)) continue;
      const QByteArray k = Span(cn_, np.first.get()) + ":";
      const QByteArray sub(col + 2, ' ');
      if (ov && ov->type == YNode::Map && nv->type == YNode::Map && !nv->flow)
        lines << k + "\n" + sub + PartialBlock(ov, nv, col + 2);
      else if (nv->type != YNode::Scalar && !nv->flow)
        lines << k + "\n" + sub + Block(nv, col + 2);
      else
        lines << k + " " + Flow(nv);
    }
    return lines.join("\n" + QByteArray(col, ' '));
  }

  void Insert(const YNode *u, const YNode *key, const YNode *n, const YNode *o) {
    const QByteArray k = Span(cn_, key);
    const bool partial = o && o->type == YNode::Map && n->type == YNode::Map;
    if (u->flow) {
      const size_t pos = u->end > u->start ? u->end - 1 : u->start; /* the closing brace */
      splices.push_back(Splice{pos, pos,
                               (u->pairs.empty() ? QByteArray() : QByteArray(", ")) + k + ": " +
                                   (partial ? PartialFlow(o, n) : Flow(n)),
                               order_++});
      return;
    }
    size_t last_end = u->end;
    int nl = user_.indexOf('\n', static_cast<int>(last_end));
    QByteArray t;
    size_t pos = 0;
    if (nl < 0) {
      pos = static_cast<size_t>(user_.size());
      t = "\n";
    } else {
      pos = static_cast<size_t>(nl) + 1;
    }
    const QByteArray ind(u->col, ' ');
    const bool block_new = (n->type != YNode::Scalar && !n->flow);
    const QByteArray sub(u->col + 2, ' ');
    if (partial && block_new)
      t += ind + k + ":\n" + sub + PartialBlock(o, n, u->col + 2) + "\n";
    else if (partial)
      t += ind + k + ": " + PartialFlow(o, n) + "\n";
    else
      t += ind + k + ":" + (block_new ? "\n" + sub + Block(n, u->col + 2) : " " + Flow(n)) + "\n";
    splices.push_back(Splice{pos, pos, t, order_++});
  }

  /* The user wrote the field in another unit ("yaw_rad" where the writer writes "yaw_deg"):
     a key of the user's mapping that the canonical text does not have, with the same name up to
     the unit suffix, is replaced by the canonical key and value. */
  bool ReplaceSpelling(const YNode *o, const YNode *u, const YNode *key, const YNode *n, const QString &path) {
    const QByteArray k = key->text;
    const int us = k.lastIndexOf('_');
    if (us <= 0) return false;
    const QByteArray stem = k.left(us + 1);
    for (const auto &up : u->pairs) {
      const QByteArray &uk = up.first->text;
      if (uk == k || !uk.startsWith(stem) || uk.indexOf('_', stem.size()) >= 0 || o->Get(uk)) continue;
      const YNode *uv = up.second.get();
      const bool block_here = uv->type != YNode::Scalar && !uv->flow;
      if (block_here || uv->block_scalar) return false;
      splices.push_back(Splice{up.first->start, uv->end, Span(cn_, key) + ": " + Flow(n), order_++});
      replaced << path + " (unit of " + QString::fromUtf8(uk) + ")";
      return true;
    }
    return false;
  }

  /* Whether only blanks precede @p pos on its line (the node starts its line). */
  bool StartsLine(size_t pos) const {
    for (int i = static_cast<int>(pos) - 1; i >= 0 && user_[i] != '\n'; --i)
      if (user_[i] != ' ' && user_[i] != '\t') return false;
    return true;
  }
  /* The lines [first line of @p a, end of the line of @p end_pos] of the user's text. */
  void RemoveLines(size_t a, size_t end_pos) {
    const int ls = user_.lastIndexOf('\n', static_cast<int>(a) - 1) + 1;
    int le = user_.indexOf('\n', static_cast<int>(end_pos));
    le = le < 0 ? user_.size() : le + 1;
    splices.push_back(Splice{static_cast<size_t>(ls), static_cast<size_t>(le), QByteArray(), order_++});
  }

  /* Remove a key of a block mapping: its lines, from the key's line to its value's last line.
     false when that is not possible in place (flow mapping, key not first on its line). */
  bool Remove(const YNode *um, const YNode *ukey, const YNode *uval, const QString &path) {
    if (um->flow || !StartsLine(ukey->start)) return false;
    RemoveLines(ukey->start, uval->end);
    replaced << path + " (removed)";
    return true;
  }

  /* Lists whose items were added, removed or moved: the items are aligned (longest common
     subsequence of the canonical texts), unchanged items keep their text, changed ones are
     diffed, removed ones lose their lines and new ones get a line "- item" of their own. Block
     lists only (one item per line group); false: not possible in place. */
  /* The '-' of a block-list item that starts its line ("  - item"); -1 otherwise. */
  int DashOf(const YNode *item) const {
    int k = static_cast<int>(item->start) - 1;
    while (k >= 0 && user_[k] == ' ') --k;
    if (k < 0 || user_[k] != '-' || !StartsLine(static_cast<size_t>(k))) return -1;
    return k;
  }

  bool AlignList(const YNode *o, const YNode *n, const YNode *u, const QString &path, int depth, int max_depth) {
    if (u->flow || u->items.size() != o->items.size() || u->items.empty()) return false;
    for (const auto &it : u->items)
      if (DashOf(it.get()) < 0) return false;
    const int dash0 = DashOf(u->items.front().get());
    const int col = dash0 - (user_.lastIndexOf('\n', dash0) + 1);
    const size_t a = o->items.size(), b = n->items.size();
    if (a * b > 16u * 1024u * 1024u) return false;
    std::vector<unsigned> L((a + 1) * (b + 1), 0u);
    auto at = [&](size_t i, size_t j) -> unsigned & { return L[i * (b + 1) + j]; };
    for (size_t i = a; i-- > 0;)
      for (size_t j = b; j-- > 0;)
        at(i, j) = Same(o->items[i].get(), n->items[j].get()) ? at(i + 1, j + 1) + 1 : std::max(at(i + 1, j), at(i, j + 1));
    auto match = [&](size_t i, size_t j) {
      return Same(o->items[i].get(), n->items[j].get()) && at(i, j) == at(i + 1, j + 1) + 1;
    };
    size_t i = 0, j = 0;
    // A gap between matches: pair items (diffed in place), then remove or insert the rest.
    auto flush_gap = [&](size_t i_end, size_t j_end) {
      for (; i < i_end && j < j_end; ++i, ++j)
        Diff(o->items[i].get(), n->items[j].get(), u->items[i].get(), QStringLiteral("%1[%2]").arg(path).arg(j), depth + 1,
             max_depth);
      for (; i < i_end; ++i) {
        const YNode *ui = u->items[i].get();
        RemoveLines(static_cast<size_t>(DashOf(ui)), ui->end);
        replaced << QStringLiteral("%1: an item (removed)").arg(path);
      }
      for (; j < j_end; ++j) {
        // Before the line of the next user item, or after the line of the last one.
        size_t pos = 0;
        bool lead_nl = false;
        if (i < u->items.size()) {
          pos = static_cast<size_t>(user_.lastIndexOf('\n', DashOf(u->items[i].get())) + 1);
        } else {
          const int nl = user_.indexOf('\n', static_cast<int>(u->end));
          pos = nl < 0 ? static_cast<size_t>(user_.size()) : static_cast<size_t>(nl) + 1;
          lead_nl = nl < 0;
        }
        const YNode *nj = n->items[j].get();
        const bool block_new = nj->type != YNode::Scalar && !nj->flow;
        QByteArray t = QByteArray(col, ' ') + "- " + (block_new ? Block(nj, col + 2) : Flow(nj)) + "\n";
        if (lead_nl) t.prepend('\n');
        splices.push_back(Splice{pos, pos, t, order_++});
      }
    };
    while (i < a && j < b) {
      if (match(i, j)) { // unchanged: the user's text stays
        ++i;
        ++j;
        continue;
      }
      size_t ii = i, jj = j;
      while (ii < a && jj < b && !match(ii, jj)) {
        if (at(ii + 1, jj) >= at(ii, jj + 1))
          ++ii;
        else
          ++jj;
      }
      if (ii >= a || jj >= b) break; // no further match: the rest is one gap
      flush_gap(ii, jj);
    }
    flush_gap(a, b);
    return ok;
  }

  void Diff(const YNode *o, const YNode *n, const YNode *u, const QString &path, int depth, int max_depth) {
    if (!ok || Same(o, n)) return;
    if (depth >= max_depth) {
      Replace(u, n, path);
      return;
    }
    if (o->type == YNode::Map && n->type == YNode::Map && u->type == YNode::Map) {
      for (const auto &op : o->pairs) {
        if (n->Get(op.first->text)) continue;
        // A key the new text drops: remove it from the user's mapping (root: its lines).
        for (const auto &up : u->pairs)
          if (up.first->text == op.first->text && !Remove(u, up.first.get(), up.second.get(), Join(path, op.first->text))) {
            Replace(u, n, path);
            return;
          }
      }
      for (const auto &np : n->pairs) {
        const YNode *ov = o->Get(np.first->text);
        if (ov && Same(ov, np.second.get())) continue;
        const YNode *uv = u->Get(np.first->text);
        const QString sub = Join(path, np.first->text);
        if (uv && ov)
          Diff(ov, np.second.get(), uv, sub, depth + 1, max_depth);
        else if (uv)
          Replace(uv, np.second.get(), sub);
        else if (!ReplaceSpelling(o, u, np.first.get(), np.second.get(), sub))
          Insert(u, np.first.get(), np.second.get(), ov);
      }
      return;
    }
    if (o->type == YNode::Seq && n->type == YNode::Seq && u->type == YNode::Seq && o->items.size() == n->items.size() &&
        u->items.size() == n->items.size()) {
      for (size_t i = 0; i < n->items.size(); ++i)
        Diff(o->items[i].get(), n->items[i].get(), u->items[i].get(), QStringLiteral("%1[%2]").arg(path).arg(i),
             depth + 1, max_depth);
      return;
    }
    if (o->type == YNode::Seq && n->type == YNode::Seq && u->type == YNode::Seq && AlignList(o, n, u, path, depth, max_depth))
      return;
    Replace(u, n, path);
  }

  QByteArray Apply() {
    std::sort(splices.begin(), splices.end(), [](const Splice &a, const Splice &b) {
      return a.start != b.start ? a.start > b.start : a.order > b.order;
    });
    QByteArray out = user_;
    size_t limit = static_cast<size_t>(out.size());
    for (const Splice &s : splices) {
      if (s.end > limit || s.start > s.end) return QByteArray(); /* overlapping splices */
      out.replace(static_cast<int>(s.start), static_cast<int>(s.end - s.start), s.text);
      limit = s.start;
    }
    return out;
  }

private:
  static QString Join(const QString &path, const QByteArray &key) {
    return path.isEmpty() ? QString::fromUtf8(key) : path + "." + QString::fromUtf8(key);
  }
  const QByteArray &user_, &co_, &cn_;
  int order_ = 0;
};

} // namespace

bool SceneScalar(const QByteArray &text, const QStringList &keys, QByteArray *value) {
  auto root = Parse(text);
  const YNode *n = root.get();
  for (const QString &k : keys) {
    if (!n || n->type != YNode::Map) return false;
    n = n->Get(k.toUtf8());
  }
  if (!n || n->type != YNode::Scalar) return false;
  if (value) *value = n->text;
  return true;
}

QByteArray MergeSceneText(const QByteArray &user, const QByteArray &canon_old, const QByteArray &canon_new,
                          MergeLevel level, QString *replaced) {
  if (replaced) replaced->clear();
  auto u = Parse(user), o = Parse(canon_old), n = Parse(canon_new);
  if (!u || !o || !n) return QByteArray();
  Merger m(user, canon_old, canon_new);
  m.Diff(o.get(), n.get(), u.get(), QString(), 0, level == MergeLevel::Fine ? 1000 : 1);
  if (!m.ok) return QByteArray();
  QByteArray out = m.Apply();
  if (replaced) *replaced = m.replaced.join(", ");
  return out;
}

} // namespace studio
