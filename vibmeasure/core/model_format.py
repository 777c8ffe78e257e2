"""The TOML model format, as text (imports nothing: `vibmeasure model --help` prints it at once)."""

TOML_FORMAT = """\
model file format (TOML): a type and a [parameters] table; every dimensional parameter carries its
unit as "number unit" or { value = ..., unit = "..." }; dimensionless ones are plain numbers.

  type = "sdof"                # sdof | mdof | beam | rayleigh_beam | timoshenko_beam | rod | shaft | string
  [parameters]
  m = "200 kg"
  k = "40 N/mm"
  zeta = 0.22                           # or c = "500 N s/m"; loss_factor = 0.02 alone or added

  type = "mdof"
  [parameters]
  M = { value = [[2, 0], [0, 1]], unit = "kg" }
  K = { value = [[3000, -1000], [-1000, 1000]], unit = "N/m" }
  modal_zeta = [0.02, 0.02]             # or C = {...} in N s/m, or rayleigh = [alpha, beta]

  type = "beam"                         # Euler-Bernoulli
  [parameters]
  E = "210 GPa"
  I = "833 mm^4"
  rho = "7850 kg/m^3"
  A = "100 mm^2"
  L = "0.5 m"
  bc = "cantilever"                     # cantilever | simply-supported | clamped-clamped | free-free | clamped-pinned
  zeta = 0.01

  rayleigh_beam: as beam (adds rotary inertia); timoshenko_beam: as beam plus G (or nu) and kappa
  (shear coefficient, 5/6 for a rectangle); rod: E, rho, L, bc (fixed-free | fixed-fixed | free-free),
  zeta, A (for its FRF); shaft: G, rho, L, bc, zeta, J; string: T (N), mu (kg/m), L, zeta.

units: mass kg g t lb; stiffness N/m N/mm kN/m kN/mm lbf/in; damping N s/m kN s/m; length m mm cm in;
modulus Pa kPa MPa GPa; density kg/m^3 g/cm^3; area m^2 mm^2; second moment m^4 mm^4; force N;
linear density kg/m g/m; inertia kg m^2; torsion N m/rad, N m s/rad.
A model without damping is loaded with a QualityWarning (zeta = 0)."""
