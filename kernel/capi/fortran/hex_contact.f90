!> The hex element and the contact kernel from Fortran, as a host's own mesh
!> and contact loop would call them (granbed_hex_reference,
!> granbed_hex_forces, granbed_project_node, granbed_face_force), checked
!> against mechanics rather than against the C examples:
!>  1. the patch test of physics.md section 2.4: a 2x2x2 patch of hexes whose
!>     interior node is moved off the grid in the reference configuration,
!>     deformed homogeneously (x = F X + c, plastic for B2). Assembled into
!>     the patch's 27 nodes, the interior node carries no force (1e-13 of the
!>     largest nodal force), the forces balance, every element's Kirchhoff
!>     stress is the material point's (granbed_update_points with the same F)
!>     and there is no hourglass energy; the top face carries the axial
!>     force P_zz A0; without the optional tau and info the forces are the
!>     same;
!>  2. a node-to-face constraint on a tilted quad with unequal corner masses:
!>     the projection's foot lies on the face, the corner forces are
!>     -w_i times the slave force (the (xyz, corner) layout), momentum
!>     balances, and after the corrector x = x_pred + dt^2 f / m the gap at
!>     the contact point is closed; with friction the tangential force sits
!>     on the Coulomb cap;
!>  3. a bad argument (a zero time step) is refused with its code.
!> Exit status 0 if all hold.
program hex_contact_f
  use, intrinsic :: iso_c_binding, only: c_double, c_int32_t
  use granbed
  implicit none
  integer, parameter :: nel = 8
  real(c_double), parameter :: h = 0.5e-3_c_double
  real(c_double) :: props(GRANBED_VUMAT_NPROPS), grid(3, 27), x_ref(3, 8, nel), x(3, 8, nel)
  real(c_double) :: reference(GRANBED_HEX_REFERENCE_LEN, nel), cp_inv(6, nel), f(3, 8, nel)
  real(c_double) :: tau(6, nel), nodal(3, 27), fmat(3, 3), f_row(9, 1), cp_point(6, 1), tau_point(6, 1)
  real(c_double) :: shift(3), fmax, tau_scale, top, expect_top
  type(granbed_point_info) :: info(nel), info_point(1)
  integer(c_int32_t) :: status(nel), status_point(1), ierr
  integer :: failures, i, j, k, e, a, b, c, corner
  integer, parameter :: offsets(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, &
       0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1], [3, 8])
  integer :: conn(8, nel)

  failures = 0
  call granbed_preset_props('B2', props, ierr)
  call check('preset B2', ierr == GRANBED_OK)

  ! 1. The patch: nodes on a 3x3x3 grid of spacing h, node (i, j, k) at
  ! 1 + i + 3j + 9k; the interior node (1, 1, 1) = 14 moved off the grid.
  do k = 0, 2
     do j = 0, 2
        do i = 0, 2
           grid(:, 1 + i + 3 * j + 9 * k) = h * [i, j, k]
        end do
     end do
  end do
  grid(:, 14) = grid(:, 14) + h * [0.1_c_double, -0.07_c_double, 0.05_c_double]
  e = 0
  do c = 0, 1
     do b = 0, 1
        do a = 0, 1
           e = e + 1
           do corner = 1, 8
              conn(corner, e) = 1 + (a + offsets(1, corner)) + 3 * (b + offsets(2, corner)) &
                   + 9 * (c + offsets(3, corner))
              x_ref(:, corner, e) = grid(:, conn(corner, e))
           end do
        end do
     end do
  end do
  call granbed_hex_reference(nel, x_ref, reference, status, ierr)
  call check('reference', ierr == GRANBED_OK .and. all(status == GRANBED_OK))
  call check('patch volume', abs(sum(reference(1, :)) - (2 * h)**3) <= 1e-12_c_double * (2 * h)**3)

  ! F row by row (compression along z with shear), applied with a shift.
  fmat = transpose(reshape([1.01_c_double, 0.02_c_double, 0.0_c_double, &
       0.0_c_double, 0.99_c_double, 0.01_c_double, &
       0.0_c_double, 0.0_c_double, 0.9_c_double], [3, 3]))
  shift = [1e-4_c_double, -2e-4_c_double, 3e-4_c_double]
  do e = 1, nel
     do corner = 1, 8
        x(:, corner, e) = matmul(fmat, x_ref(:, corner, e)) + shift
     end do
  end do
  call granbed_state_init(nel, cp_inv, ierr)
  call granbed_hex_forces(props, .true., GRANBED_DEFAULT_HOURGLASS_KAPPA, nel, reference, x, &
       cp_inv, f, status, ierr, tau=tau, info=info)
  call check('hex forces', ierr == GRANBED_OK .and. all(status == GRANBED_OK))
  ! Without the optional outputs (NULL for the C ABI): the same forces.
  block
    real(c_double) :: cp_again(6, nel), f_again(3, 8, nel)
    call granbed_state_init(nel, cp_again, ierr)
    call granbed_hex_forces(props, .true., GRANBED_DEFAULT_HOURGLASS_KAPPA, nel, reference, x, &
         cp_again, f_again, status, ierr)
    call check('hex forces without tau and info', ierr == GRANBED_OK .and. all(f_again == f) &
         .and. all(cp_again == cp_inv))
  end block
  nodal = 0
  do e = 1, nel
     do corner = 1, 8
        nodal(:, conn(corner, e)) = nodal(:, conn(corner, e)) + f(:, corner, e)
     end do
  end do
  fmax = maxval(abs(nodal))
  print '(a,es10.3,a,es10.3,a)', 'hex_contact_f: interior node force ', maxval(abs(nodal(:, 14))), &
       ' N of ', fmax, ' N'
  call check('patch test: no force on the interior node', maxval(abs(nodal(:, 14))) <= 1e-13_c_double * fmax)
  call check('forces balance', maxval(abs(sum(nodal, dim=2))) <= 1e-13_c_double * fmax)
  call check('no hourglass energy in a homogeneous field', all(abs(info%hourglass_energy) <= 1e-30_c_double))

  ! The material point with the same F (row-major).
  f_row(:, 1) = reshape(transpose(fmat), [9])
  call granbed_state_init(1, cp_point, ierr)
  call granbed_update_points(props, .true., 1, f_row, cp_point, GRANBED_STRESS_KIRCHHOFF, tau_point, &
       info_point, status_point, ierr)
  call check('point update', ierr == GRANBED_OK .and. info_point(1)%plastic == 1)
  tau_scale = maxval(abs(tau_point))
  do e = 1, nel
     call check('element stress = point stress', maxval(abs(tau(:, e) - tau_point(:, 1))) <= 1e-9_c_double * tau_scale)
     call check('element plastic', info(e)%plastic == 1)
     call check('element state = point state', maxval(abs(cp_inv(:, e) - cp_point(:, 1))) <= 1e-12_c_double)
  end do
  ! The top face z = 2h (nodes 19-27) carries P_zz A0, A0 = (2h)^2; F upper
  ! triangular, so P_zz = tau_zz / F33.
  top = sum(nodal(3, 19:27))
  expect_top = tau_point(3, 1) / fmat(3, 3) * (2 * h)**2
  print '(a,es20.12,a,es20.12,a)', 'hex_contact_f: top face force ', top, ' N, P_zz A0 ', expect_top, ' N'
  call check('top face force = P_zz A0', abs(top - expect_top) <= 1e-9_c_double * abs(expect_top))

  call contact_checks()

  if (failures == 0) then
     print '(a)', 'hex_contact_f: all checks hold'
  else
     print '(a,i0,a)', 'hex_contact_f: ', failures, ' checks FAILED'
     stop 1
  end if

contains

  subroutine check(what, ok)
    character(len=*), intent(in) :: what
    logical, intent(in) :: ok
    if (.not. ok) then
       print '(2a)', 'FAIL ', what
       failures = failures + 1
    end if
  end subroutine check

  !> 2. and 3.: a node behind a tilted quad.
  subroutine contact_checks()
    real(c_double), parameter :: dt2 = 1e-12_c_double, mu = 0.2_c_double
    real(c_double) :: quad(3, 4), p(3), foot(3), n(3), tangent(3), moved_slave(3), moved(3, 4)
    real(c_double) :: gap_after, ft, balance(3)
    type(granbed_quad_projection) :: q
    type(granbed_node_face) :: con
    type(granbed_node_face_force) :: force
    integer :: m
    ! A 1 mm square tilted about x by atan(0.2) (normal (0, -0.2, 1)/|.|).
    quad = reshape([0.0_c_double, 0.0_c_double, 0.0_c_double, 1e-3_c_double, 0.0_c_double, 0.0_c_double, &
         1e-3_c_double, 1e-3_c_double, 0.2e-3_c_double, 0.0_c_double, 1e-3_c_double, 0.2e-3_c_double], [3, 4])
    p = [0.3e-3_c_double, 0.7e-3_c_double, 0.14e-3_c_double - 2e-6_c_double]
    call granbed_project_node(p, quad, q, ierr)
    call check('projection', ierr == GRANBED_OK .and. q%inside == 1)
    foot = matmul(quad, q%weights)
    n = [0.0_c_double, -0.2_c_double, 1.0_c_double] / sqrt(1.04_c_double)
    call check('the foot is the weighted corners', maxval(abs(foot - q%point)) <= 1e-18_c_double)
    call check('normal of the tilted face', maxval(abs(q%normal - n)) <= 1e-15_c_double)
    call check('gap = n.(p - foot) < 0', abs(q%gap - dot_product(n, p - foot)) <= 1e-18_c_double &
         .and. q%gap < 0)
    call check('the foot is the weights of (xi, eta)', abs(q%weights(3) - &
         0.25_c_double * (1 + q%xi) * (1 + q%eta)) <= 1e-15_c_double)

    con%slave_mass = 3e-9_c_double
    con%slave_x_n = p + 3e-6_c_double * n
    con%slave_x_pred = p
    con%master_mass = [1e-9_c_double, 2e-9_c_double, 4e-9_c_double, 8e-9_c_double]
    con%master_x_n = quad
    con%master_x_pred = quad
    con%weights = q%weights
    con%normal = q%normal
    con%gap = q%gap
    call granbed_face_force(con, 1.0_c_double, 0.0_c_double, dt2, force, ierr)
    call check('face force', ierr == GRANBED_OK .and. force%normal > 0)
    balance = force%slave + sum(force%master, dim=2)
    call check('momentum balance', maxval(abs(balance)) <= 1e-15_c_double * force%normal)
    do m = 1, 4
       call check('corner force = -w_i slave force', &
            maxval(abs(force%master(:, m) + q%weights(m) * force%slave)) <= 1e-15_c_double * force%normal)
    end do
    moved_slave = con%slave_x_pred + dt2 * force%slave / con%slave_mass
    do m = 1, 4
       moved(:, m) = con%master_x_pred(:, m) + dt2 * force%master(:, m) / con%master_mass(m)
    end do
    gap_after = dot_product(con%normal, moved_slave - matmul(moved, con%weights))
    print '(a,es10.3,a,es10.3,a,es12.5,a)', 'hex_contact_f: gap before ', con%gap, ' m, after ', &
         gap_after, ' m, F_n ', force%normal, ' N'
    call check('gap closed by the corrector', abs(gap_after) <= 1e-12_c_double * abs(con%gap))

    ! Sliding along the face's x edge by 5 um in the step: friction on the cap.
    tangent = [1.0_c_double, 0.0_c_double, 0.0_c_double]
    con%slave_x_pred = p + 5e-6_c_double * tangent
    call granbed_project_node(con%slave_x_pred, quad, q, ierr)
    con%weights = q%weights
    con%gap = q%gap
    call granbed_face_force(con, 1.0_c_double, mu, dt2, force, ierr)
    ft = norm2(force%friction)
    print '(a,f0.12,a,i0)', 'hex_contact_f: sliding |F_t| / F_n = ', ft / force%normal, ', slipping ', &
         force%slipping
    call check('Coulomb cap', ierr == GRANBED_OK .and. force%slipping == 1 .and. &
         abs(ft - mu * force%normal) <= 1e-12_c_double * force%normal .and. force%friction(1) < 0)

    ! 3. A zero time step is an argument error, and the force is not written.
    force%normal = -1
    call granbed_face_force(con, 1.0_c_double, mu, 0.0_c_double, force, ierr)
    print '(2a)', 'hex_contact_f: dt^2 = 0: ', trim(granbed_message(ierr))
    call check('dt^2 = 0 refused', ierr == GRANBED_ERR_INVALID_ARGUMENT .and. force%normal == -1)
  end subroutine contact_checks
end program hex_contact_f
