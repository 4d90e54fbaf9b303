// navstudio: navsim tradeoff as a child process and its result dialog (tradeoff_run.h).
#include "tradeoff_run.h"

#include <QDialogButtonBox>
#include <QDir>
#include <QFile>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QPixmap>
#include <QPushButton>
#include <QScrollArea>
#include <QVBoxLayout>

#include "navcore/nav_paths.h"

namespace studio {

TradeoffRun::TradeoffRun(QObject *parent) : QObject(parent) {
  char buf[4096];
  program_ = nav_paths_program("navsim", buf, sizeof buf) ? QString::fromLocal8Bit(buf) : QStringLiteral("navsim");
  connect(&proc_, qOverload<int, QProcess::ExitStatus>(&QProcess::finished), this,
          [this](int code, QProcess::ExitStatus st) {
            const QString err = QString::fromLocal8Bit(proc_.readAllStandardError()).trimmed();
            const bool ok = st == QProcess::NormalExit && code == 0;
            emit Finished(ok, ok ? err : (err.isEmpty() ? tr("navsim tradeoff exited with %1").arg(code) : err));
          });
  connect(&proc_, &QProcess::errorOccurred, this, [this](QProcess::ProcessError e) {
    if (e == QProcess::FailedToStart) emit Finished(false, tr("cannot start %1: %2").arg(program_, proc_.errorString()));
  });
}

TradeoffRun::~TradeoffRun() {
  if (proc_.state() != QProcess::NotRunning) {
    proc_.kill();
    proc_.waitForFinished(5000);
  }
}

bool TradeoffRun::Start(const QString &scene, const QString &out_dir, int runs, QString *error) {
  if (IsBusy()) {
    if (error) *error = tr("a tradeoff is already running");
    return false;
  }
  out_dir_ = out_dir;
  QStringList args{"tradeoff", scene, "--out", out_dir, "--quiet"};
  if (runs > 0) args << "--runs" << QString::number(runs);
  proc_.setProcessChannelMode(QProcess::SeparateChannels);
  proc_.start(program_, args);
  return true;
}

QDialog *MakeTradeoffDialog(QWidget *parent, const QString &dir, const std::function<void(const QString &)> &open_scene) {
  auto *d = new QDialog(parent);
  d->setObjectName("tradeoffDialog");
  d->setWindowTitle(QObject::tr("Speed against error: %1").arg(dir));
  auto *lay = new QVBoxLayout(d);
  QString text;
  QFile sf(dir + "/summary.json");
  if (sf.open(QIODevice::ReadOnly)) {
    const QJsonObject o = QJsonDocument::fromJson(sf.readAll()).object();
    const QJsonObject rec = o.value("recommended").toObject();
    text = QObject::tr("Recommended: <b>%1</b> (%2): %3 s CPU per run against %4 s for the full model, every "
                       "requirement within %5 % of the full model's value (%6 per variant, seed %7).")
               .arg(rec.value("variant").toString().toHtmlEscaped(), rec.value("change").toString().toHtmlEscaped())
               .arg(rec.value("cpu_s_per_run").toDouble(), 0, 'g', 3)
               .arg(rec.value("full_cpu_s_per_run").toDouble(), 0, 'g', 3)
               .arg(100.0 * o.value("tolerance").toDouble(), 0, 'g', 3)
               .arg(o.value("runs").toInt() == 1 ? QObject::tr("1 run")
                                                 : QObject::tr("%1 runs").arg(o.value("runs").toInt()))
               .arg(o.value("seed").toVariant().toString());
  } else {
    text = QObject::tr("%1/summary.json cannot be read.").arg(dir.toHtmlEscaped());
  }
  auto *label = new QLabel(text, d);
  label->setObjectName("tradeoffRecommendation");
  label->setWordWrap(true);
  lay->addWidget(label);
  auto *area = new QScrollArea(d);
  auto *inner = new QWidget(area);
  auto *il = new QVBoxLayout(inner);
  const QStringList charts = QDir(dir).entryList({"tradeoff_*.png"}, QDir::Files, QDir::Name);
  for (const QString &c : charts) {
    QPixmap pm(dir + "/" + c);
    if (pm.isNull()) continue;
    auto *img = new QLabel(inner);
    img->setObjectName("tradeoffChart");
    img->setPixmap(pm);
    img->setToolTip(c);
    il->addWidget(img);
  }
  area->setWidget(inner);
  area->setMinimumSize(1040, 600);
  lay->addWidget(area);
  auto *buttons = new QDialogButtonBox(QDialogButtonBox::Close, d);
  QPushButton *open = buttons->addButton(QObject::tr("Open recommended scene"), QDialogButtonBox::ActionRole);
  open->setObjectName("openRecommended");
  open->setEnabled(QFile::exists(dir + "/recommended.yaml"));
  QObject::connect(open, &QPushButton::clicked, d, [d, dir, open_scene] {
    d->accept();
    open_scene(dir + "/recommended.yaml");
  });
  QObject::connect(buttons, &QDialogButtonBox::rejected, d, &QDialog::reject);
  lay->addWidget(buttons);
  return d;
}

} // namespace studio
