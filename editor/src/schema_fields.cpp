#include "schema_fields.h"

#include <QStringList>

#include <cstdlib>
#include <cstring>
#include <memory>

namespace studio {

namespace {
struct Table {
  nav_schema_key *keys = nullptr;
  size_t n = 0;
  Table() {
    if (nav_schema_keys(&keys, &n) != NAV_OK) {
      keys = nullptr;
      n = 0;
    }
  }
  ~Table() { std::free(keys); }
  Table(const Table &) = delete;
  Table &operator=(const Table &) = delete;
};

const Table &TheTable() {
  static const Table t; // thread-safe initialisation (C++11)
  return t;
}

QString Number(double v) {
  return QString::number(v, 'g', 10);
}
} // namespace

const nav_schema_key &SchemaKey(const char *path) {
  const Table &t = TheTable();
  const nav_schema_key *k = nav_schema_find(t.keys, t.n, path);
  Q_ASSERT_X(k != nullptr, "SchemaKey", path);
  if (k) return *k;
  static nav_schema_key none = [] {
    nav_schema_key z;
    std::memset(&z, 0, sizeof z);
    z.scale = 1.0;
    z.alt_of = -1;
    z.doc = "";
    return z;
  }();
  return none;
}

QString DisplayUnit(const char *unit) {
  if (!unit || std::strcmp(unit, "1") == 0) return QString();
  QString u = QString::fromUtf8(unit);
  u.replace(QStringLiteral("sqrt(h)"), QStringLiteral("√h"));
  u.replace(QStringLiteral("sqrt(Hz)"), QStringLiteral("√Hz"));
  u.replace(QStringLiteral("sqrt(s)"), QStringLiteral("√s"));
  u.replace(QStringLiteral("^2"), QStringLiteral("²"));
  u.replace(QStringLiteral("^3"), QStringLiteral("³"));
  if (u == QStringLiteral("ug") || u.startsWith(QStringLiteral("ug/"))) u.replace(0, 2, QStringLiteral("µg"));
  return u;
}

QString KeyHelp(const nav_schema_key &k) {
  QStringList parts;
  if (k.doc && k.doc[0]) parts << QString::fromUtf8(k.doc);
  const QString unit = DisplayUnit(k.unit);
  QString range;
  if (k.bounds & NAV_SCHEMA_MIN)
    range +=
        ((k.bounds & NAV_SCHEMA_MIN_EXCLUSIVE) ? QStringLiteral("> ") : QStringLiteral("≥ ")) + Number(k.min);
  if (k.bounds & NAV_SCHEMA_MAX)
    range += (range.isEmpty() ? QString() : QStringLiteral(", ")) + QStringLiteral("≤ ") + Number(k.max);
  if (!range.isEmpty())
    parts << QStringLiteral("range %1%2").arg(range, unit.isEmpty() ? QString() : QStringLiteral(" ") + unit);
  if (k.has_default &&
      (k.type == NAV_SCHEMA_NUMBER || k.type == NAV_SCHEMA_VEC3_SCALAR || k.type == NAV_SCHEMA_INTEGER))
    parts << QStringLiteral("default %1").arg(Number(k.default_value[0]));
  return parts.join(QStringLiteral("; "));
}

} // namespace studio
