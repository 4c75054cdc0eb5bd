#include "app/studies/bench_bullet.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "engine/geometry.hpp"
#include "engine/rotation.hpp"
#include "engine/stopwatch.hpp"
#include "tools_scripted/instrument.hpp"

#ifdef VDMSIM_HAVE_BULLET
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#endif

namespace vdmsim {

std::string describe(const BulletSettings& s) {
  std::ostringstream o;
  o << "btSoftBody: " << s.substeps << " steps per frame, piterations " << s.piterations << ", kLST "
    << s.link_stiffness << ", kPR " << s.pressure_pa << " Pa x V_0, kVC " << s.volume_modulus << " Pa / V_0, kDP "
    << s.damping << ", kCHR " << s.contact_hardness << ", margin " << s.margin << " m, SDF voxel " << s.sdf_voxel
    << " m";
  return o.str();
}

#ifndef VDMSIM_HAVE_BULLET

bool bullet_available() { return false; }

struct BulletProbe::Impl {};

BulletProbe::BulletProbe(const PreparedScene&, const BulletSettings&) {
  throw std::runtime_error("this build has no Bullet (libbullet-dev was not found when it was configured)");
}
BulletProbe::~BulletProbe() = default;
double BulletProbe::advance(int) { return 0; }
bool BulletProbe::touching() const { return false; }
double BulletProbe::volume_rel_error() const { return 0; }
double BulletProbe::max_displacement() const { return 0; }
long BulletProbe::nodes() const { return 0; }

#else

bool bullet_available() { return true; }

namespace {

using vdm::Clock;
using vdm::ms_since;

// The capsule's Bullet transform: btCapsuleShapeZ is centred at the origin along z.
btTransform capsule_transform(const vdm::Capsule& c) {
  const vdm::Vec3 d = c.p1 - c.p0;
  const double len = d.norm();
  const Eigen::Quaterniond q =
      vdm::rotation_between(vdm::Vec3::UnitZ(), len > 0 ? vdm::Vec3(d / len) : vdm::Vec3::UnitZ());
  const vdm::Vec3 centre = 0.5 * (c.p0 + c.p1);
  return btTransform(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
                     btVector3(btScalar(centre.x()), btScalar(centre.y()), btScalar(centre.z())));
}

const tools::InstrumentDef& scene_probe(const SceneDef& scene) {
  const tools::InstrumentDef* probe_def = nullptr;
  for (const tools::InstrumentDef& in : scene.instruments)
    if (in.type == tools::InstrumentDef::Type::probe) probe_def = &in;
  if (!probe_def) throw std::runtime_error("the Bullet case needs a scene with a probe");
  return *probe_def;
}

}  // namespace

// A Bullet world with gravity off (the VDM probe case has none), owning what it needs, and
// the probe case's state.
struct BulletProbe::Impl {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::unique_ptr<btSoftBody> body;
  std::unique_ptr<btCapsuleShapeZ> probe_shape;
  std::unique_ptr<btDefaultMotionState> probe_motion;
  std::unique_ptr<btRigidBody> probe;

  const vdm::TissueModel& m;
  const tools::InstrumentDef& probe_def;
  BulletSettings set;
  double dt = 0;
  vdm::NodeMat pos;
  bool touching = false;
  double volume_rel_error = 0, max_displacement = 0;

  Impl(const PreparedScene& ps, const BulletSettings& s) : m(ps.organ().model), probe_def(scene_probe(ps.scene)), set(s) {
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_broadphase = &broadphase;
    info.m_dispatcher = &dispatcher;
    info.m_gravity.setZero();
    info.air_density = 0;
    info.m_sparsesdf.Initialize();
    info.m_sparsesdf.setDefaultVoxelsz(btScalar(set.sdf_voxel));
    info.m_sparsesdf.Reset();
    world.setGravity(btVector3(0, 0, 0));

    // The same surface: nodes, the model's unique edges as links, its triangles as faces.
    // Mass rho V_0 spread by area (as VDM's V_i); nodes the scene fixes have no inverse mass.
    std::vector<btVector3> x(static_cast<size_t>(m.n));
    std::vector<btScalar> mass(static_cast<size_t>(m.n));
    vdm::NodeMat area(m.n, 3);
    vdm::distributed_area_vectors(m.rest.positions, m.rest.triangles, area);
    double area_sum = 0;
    for (int i = 0; i < m.n; ++i) area_sum += area.row(i).norm();
    for (int i = 0; i < m.n; ++i) {
      x[i] = btVector3(btScalar(m.rest.positions(i, 0)), btScalar(m.rest.positions(i, 1)),
                       btScalar(m.rest.positions(i, 2)));
      const bool fixed = m.held(i, 0) && m.held(i, 1) && m.held(i, 2);
      mass[i] = fixed ? btScalar(0) : btScalar(m.density * m.rest_volume * area.row(i).norm() / area_sum);
    }
    body = std::make_unique<btSoftBody>(&info, m.n, x.data(), mass.data());
    btSoftBody& b = *body;
    btSoftBody::Material* mat = b.appendMaterial();
    mat->m_kLST = btScalar(set.link_stiffness);
    for (const auto& e : m.edges) b.appendLink(e[0], e[1], mat, false);
    for (int k = 0; k < m.rest.triangle_count(); ++k)
      b.appendFace(m.rest.triangles(k, 0), m.rest.triangles(k, 1), m.rest.triangles(k, 2), mat);
    b.m_cfg.piterations = set.piterations;
    b.m_cfg.kPR = btScalar(set.pressure_pa * m.rest_volume);
    b.m_cfg.kVC = btScalar(set.volume_modulus / m.rest_volume);
    b.m_cfg.kDP = btScalar(set.damping);
    b.m_cfg.kCHR = btScalar(set.contact_hardness);
    b.m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
    b.getCollisionShape()->setMargin(btScalar(set.margin));
    b.setPose(true, false);  // rest volume for kVC
    b.randomizeConstraints();
    world.addSoftBody(&b);

    // The probe: a kinematic capsule moved along the scene's script.
    dt = ps.scene.dt;
    const vdm::Capsule cap = tools::probe_capsule(probe_def, tools::pose_at(probe_def, 0.0));
    probe_shape = std::make_unique<btCapsuleShapeZ>(btScalar(cap.radius), btScalar((cap.p1 - cap.p0).norm()));
    probe_motion = std::make_unique<btDefaultMotionState>(capsule_transform(cap));
    btRigidBody::btRigidBodyConstructionInfo ci(0, probe_motion.get(), probe_shape.get());
    probe = std::make_unique<btRigidBody>(ci);
    probe->setCollisionFlags(probe->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    probe->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(probe.get());
    pos.resize(m.n, 3);
  }

  ~Impl() {
    if (probe) world.removeRigidBody(probe.get());
    if (body) world.removeSoftBody(body.get());
  }

  // Frame f is the scene at f dt, as in vdmsim's runs: frame 0 takes no step (the body at rest,
  // the probe at its t = 0 pose), frame f >= 1 steps from (f - 1) dt to f dt.
  double advance(int f) {
    const double t0 = (f - 1) * dt, h = dt / set.substeps;
    vdm::Capsule cap = tools::probe_capsule(probe_def, tools::pose_at(probe_def, f * dt));
    const auto start = Clock::now();
    for (int j = 1; f > 0 && j <= set.substeps; ++j) {
      cap = tools::probe_capsule(probe_def, tools::pose_at(probe_def, t0 + j * h));
      probe_motion->setWorldTransform(capsule_transform(cap));
      world.stepSimulation(btScalar(h), 0);
    }
    const double ms = ms_since(start);
    // Measured outside the timed part: the deformed surface's volume, and contact.
    double closest = 1e30;
    for (int i = 0; i < m.n; ++i) {
      const btVector3& p = body->m_nodes[i].m_x;
      pos.row(i) = vdm::Vec3(p.x(), p.y(), p.z()).transpose();
      vdm::Vec3 sp, nrm;
      closest = std::min(closest, vdm::capsule_distance(cap, pos.row(i).transpose(), sp, nrm));
    }
    if (!pos.allFinite()) throw std::runtime_error("Bullet's soft body blew up (non-finite positions)");
    max_displacement = std::max(max_displacement, (pos - m.rest.positions).rowwise().norm().maxCoeff());
    const double v = vdm::enclosed_volume(pos, m.rest.triangles, m.origin);
    volume_rel_error = std::abs(v - m.rest_volume) / m.rest_volume;
    touching = closest < set.margin + 0.05 * cap.radius;
    return ms;
  }
};

BulletProbe::BulletProbe(const PreparedScene& ps, const BulletSettings& settings)
    : impl_(std::make_unique<Impl>(ps, settings)) {}
BulletProbe::~BulletProbe() = default;
double BulletProbe::advance(int f) { return impl_->advance(f); }
bool BulletProbe::touching() const { return impl_->touching; }
double BulletProbe::volume_rel_error() const { return impl_->volume_rel_error; }
double BulletProbe::max_displacement() const { return impl_->max_displacement; }
long BulletProbe::nodes() const { return impl_->m.n; }

#endif

BulletRun run_bullet_probe(const PreparedScene& ps, int frames, int warmup, const BulletSettings& settings) {
  BulletProbe probe(ps, settings);
  BulletRun run;
  run.nodes = probe.nodes();
  run.iterations = settings.substeps * settings.piterations;
  for (int f = 0; f < frames; ++f) {
    const double ms = probe.advance(f);
    run.volume_rel_error = std::max(run.volume_rel_error, probe.volume_rel_error());
    run.contact_frames += probe.touching() ? 1 : 0;
    if (probe.touching() && f > warmup) run.step_ms.push_back(ms);
  }
  run.max_displacement = probe.max_displacement();
  return run;
}

}  // namespace vdmsim
